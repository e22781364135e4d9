// The visible integral from its boundary (docs/boundary-integral.md, docs/gpu.md), one
// configuration per invocation: polygon 0 of a configuration is the light, the others its
// occluders, all single loops on the unit sphere in the shading frame, already clipped to the
// horizon. Every edge of every polygon is cut where another polygon's boundary meets its great
// circle; each sub-arc is a piece of V's boundary in the edge's direction when V lies on its
// left only, against it when V lies on its right only (V = light less the occluders, sides by
// winding numbers, collinear edges counting half a turn), and the pieces' edge integrals
// (000 Eq. 9) sum to 2π times the visible form factor. The same rule as
// `geometry::boundary_pieces`, in bounded loops: MAX_EDGES edges per configuration (the host
// sends larger ones to the CPU) and MAX_CUTS cuts per edge (beyond it the invocation reports
// an overflow and the host finishes the configuration on the CPU).
//
// `real` is f32 here; the host substitutes f64 where the adapter has SHADER_F64, with the
// trigonometric functions below written for it (WGSL's built-ins are 32-bit).

ENABLE_DIRECTIVES
alias real = REAL;
alias vec3r = vec3<REAL>;

const MAX_EDGES: u32 = 64u;
const MAX_CUTS: u32 = 64u;
const PI: real = 3.14159265358979323846;
const TAU: real = 6.28318530717958647692;
// Collinearity and "on the circle" (EPS_LINE of the CPU, scaled to the precision).
const EPS_LINE: real = EPS_LINE_VALUE;

struct Config {
    first_poly: u32,
    poly_count: u32,
}

struct Poly {
    first_vertex: u32,
    vertex_count: u32,
}

@group(0) @binding(0) var<storage, read> vertices: array<vec4<real>>;
@group(0) @binding(1) var<storage, read> polys: array<Poly>;
@group(0) @binding(2) var<storage, read> configs: array<Config>;
// Per configuration: the visible form factor, and a status (0 done, 1 overflow).
@group(0) @binding(3) var<storage, read_write> results: array<vec2<real>>;

struct Edge {
    a: vec3r,
    b: vec3r,
    u: vec3r,
    n: vec3r,
    theta: real,
    proper: bool,
    poly: u32,
}

var<private> edges: array<Edge, MAX_EDGES>;
var<private> poly_first: array<u32, MAX_EDGES>;
var<private> poly_end: array<u32, MAX_EDGES>;
var<private> cuts: array<real, MAX_CUTS>;
var<private> collinear_edges: array<u32, MAX_EDGES>;
var<private> collinear_count: u32;

ATAN2_DEFINITION

fn make_edge(a0: vec3r, b0: vec3r, poly: u32) -> Edge {
    let a = normalize(a0);
    let b = normalize(b0);
    // a × b as ½ (a + b) × (b − a): relative precision for short edges.
    let w = cross(a + b, b - a) * 0.5;
    let s = length(w);
    let c = dot(a, b);
    var e: Edge;
    e.a = a;
    e.b = b;
    e.proper = s > 0.0;
    if e.proper {
        e.n = w / s;
        e.theta = atan2r(s, c);
    } else {
        e.n = vec3r(0.0, 0.0, 1.0);
        e.theta = 0.0;
    }
    e.u = cross(e.n, a);
    e.poly = poly;
    return e;
}

fn param(e: Edge, p: vec3r) -> real {
    return atan2r(dot(p, e.u), dot(p, e.a));
}

fn point_at(e: Edge, t: real) -> vec3r {
    if t <= 0.0 {
        return e.a;
    }
    if t >= e.theta {
        return e.b;
    }
    return e.a * cosr(t) + e.u * sinr(t);
}

fn is_collinear(e: Edge, f: Edge) -> bool {
    return e.proper && f.proper && abs(dot(e.n, f.a)) <= EPS_LINE && abs(dot(e.n, f.b)) <= EPS_LINE
        && abs(dot(f.n, e.a)) <= EPS_LINE && abs(dot(f.n, e.b)) <= EPS_LINE;
}

fn contains_on_circle(e: Edge, p: vec3r) -> bool {
    let t = param(e, p);
    return t > 0.0 && t < e.theta;
}

fn is_collinear_edge(fi: u32) -> bool {
    for (var k = 0u; k < collinear_count; k++) {
        if collinear_edges[k] == fi {
            return true;
        }
    }
    return false;
}

// (left inside, right inside) of polygon `pi` at the point m of edge e's circle, packed as
// bit 0 and bit 1.
fn sides(e: Edge, pi: u32, m: vec3r) -> u32 {
    var w: real = 0.0;
    var half_turns: i32 = 0;
    for (var fi = poly_first[pi]; fi < poly_end[pi]; fi++) {
        let f = edges[fi];
        if is_collinear_edge(fi) {
            if contains_on_circle(f, m) {
                if dot(f.n, e.n) > 0.0 {
                    half_turns += 1;
                } else {
                    half_turns -= 1;
                }
            }
            continue;
        }
        let pa = f.a - m * dot(m, f.a);
        let pb = f.b - m * dot(m, f.b);
        w += atan2r(dot(m, cross(pa, pb)), dot(pa, pb));
    }
    let h = PI * real(half_turns);
    var out = 0u;
    if (w + h) / TAU > 0.5 {
        out |= 1u;
    }
    if (w - h) / TAU > 0.5 {
        out |= 2u;
    }
    return out;
}

fn owned_earlier(e: Edge, m: vec3r) -> bool {
    for (var k = 0u; k < collinear_count; k++) {
        let f = edges[collinear_edges[k]];
        if f.poly < e.poly && contains_on_circle(f, m) {
            return true;
        }
    }
    return false;
}

// +1 a piece along e, −1 against it, 0 none.
fn decide(e: Edge, m: vec3r, poly_count: u32) -> i32 {
    if owned_earlier(e, m) {
        return 0;
    }
    var left = true;
    var right = false;
    if e.poly != 0u {
        let s = sides(e, 0u, m);
        left = false;
        right = (s & 2u) != 0u;
    }
    for (var pi = 1u; pi < poly_count; pi++) {
        if !left && !right {
            break;
        }
        if pi == e.poly {
            continue;
        }
        let s = sides(e, pi, m);
        left = left && (s & 1u) == 0u;
        right = right && (s & 2u) == 0u;
    }
    if left && !right {
        return 1;
    }
    if right && !left {
        return -1;
    }
    return 0;
}

// The edge integral of the arc a → b (000 Eq. 9 before its 1/2π): θ (a × b)_z / |a × b|.
fn edge_integral(a: vec3r, b: vec3r) -> real {
    let w = cross(a + b, b - a) * 0.5;
    let s = length(w);
    if s <= 0.0 {
        return 0.0;
    }
    return atan2r(s, dot(a, b)) * w.z / s;
}

fn add_cut(count: ptr<function, u32>, t: real, theta: real) -> bool {
    if t > 0.0 && t < theta {
        if *count >= MAX_CUTS {
            return false;
        }
        cuts[*count] = t;
        *count += 1u;
    }
    return true;
}

@compute @workgroup_size(64)
fn main(@builtin(global_invocation_id) id: vec3<u32>) {
    let ci = id.x;
    if ci >= arrayLength(&configs) {
        return;
    }
    let config = configs[ci];
    // The edges, polygon by polygon.
    var edge_count = 0u;
    for (var p = 0u; p < config.poly_count; p++) {
        let poly = polys[config.first_poly + p];
        poly_first[p] = edge_count;
        for (var k = 0u; k < poly.vertex_count; k++) {
            let a = vertices[poly.first_vertex + k].xyz;
            let b = vertices[poly.first_vertex + (k + 1u) % poly.vertex_count].xyz;
            edges[edge_count] = make_edge(a, b, p);
            edge_count += 1u;
        }
        poly_end[p] = edge_count;
    }
    var sum: real = 0.0;
    for (var ei = 0u; ei < edge_count; ei++) {
        let e = edges[ei];
        if !e.proper {
            continue;
        }
        // The cuts, unsorted, then sorted by insertion (at most MAX_CUTS).
        var count = 0u;
        collinear_count = 0u;
        cuts[0] = 0.0;
        cuts[1] = e.theta;
        count = 2u;
        var ok = true;
        for (var fi = 0u; fi < edge_count; fi++) {
            let f = edges[fi];
            if f.poly == e.poly {
                continue;
            }
            if is_collinear(e, f) {
                collinear_edges[collinear_count] = fi;
                collinear_count += 1u;
                ok = ok && add_cut(&count, param(e, f.a), e.theta);
                ok = ok && add_cut(&count, param(e, f.b), e.theta);
                continue;
            }
            let da = dot(e.n, f.a);
            let db = dot(e.n, f.b);
            if abs(da) <= EPS_LINE {
                ok = ok && add_cut(&count, param(e, f.a), e.theta);
            }
            if abs(db) <= EPS_LINE {
                ok = ok && add_cut(&count, param(e, f.b), e.theta);
            }
            if f.proper && ((da > 0.0 && db < 0.0) || (da < 0.0 && db > 0.0)) {
                let x = f.a * abs(db) + f.b * abs(da);
                let l = length(x);
                if l > 0.0 {
                    ok = ok && add_cut(&count, param(e, x / l), e.theta);
                }
            }
        }
        if !ok {
            results[ci] = vec2<real>(0.0, 1.0);
            return;
        }
        for (var i = 1u; i < count; i++) {
            let t = cuts[i];
            var j = i;
            while j > 0u && cuts[j - 1u] > t {
                cuts[j] = cuts[j - 1u];
                j -= 1u;
            }
            cuts[j] = t;
        }
        // Each sub-arc's own term: sub-arcs of one great circle add.
        for (var j = 0u; j + 1u < count; j++) {
            let t0 = cuts[j];
            let t1 = cuts[j + 1u];
            if t1 <= t0 {
                continue;
            }
            let dir = decide(e, point_at(e, 0.5 * (t0 + t1)), config.poly_count);
            if dir != 0 {
                let p0 = point_at(e, t0);
                let p1 = point_at(e, t1);
                if dir > 0 {
                    sum += edge_integral(p0, p1);
                } else {
                    sum += edge_integral(p1, p0);
                }
            }
        }
    }
    results[ci] = vec2<real>(sum / TAU, 0.0);
}
