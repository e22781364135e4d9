// The visible integral from its boundary (docs/boundary-integral.md, docs/gpu.md), one
// configuration per invocation: polygon 0 of a configuration is the light, the others its
// occluders, all single loops on the unit sphere in the shading frame, each within a
// hemisphere; clipped to the horizon already, or (`clip_here`) clipped here from V's boundary
// as the lobe is: pieces kept where z ≥ 0, crossings closed by horizon arcs. Every edge of every polygon is cut where another polygon's boundary meets its great
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
const MAX_CROSSINGS: u32 = 64u;
const PI: real = 3.14159265358979323846;
const TAU: real = 6.28318530717958647692;
// Collinearity and "on the circle" (EPS_LINE of the CPU, scaled to the precision).
const EPS_LINE: real = EPS_LINE_VALUE;
// Cut parameters closer than this are one cut (a few ulps of the precision).
const CUT_RESOLUTION: real = CUT_RESOLUTION_VALUE;

struct Config {
    first_poly: u32,
    poly_count: u32,
    // 1 when the configuration has an LTC lobe (its M⁻¹ in `lobes`), 0 otherwise.
    has_lobe: u32,
    // 1 when the polygons are not clipped to the horizon: V ∩ {z ≥ 0} is taken from V's
    // boundary here, as the lobe's is.
    clip_here: u32,
}

struct Poly {
    first_vertex: u32,
    vertex_count: u32,
}

@group(0) @binding(0) var<storage, read> vertices: array<vec4<real>>;
@group(0) @binding(1) var<storage, read> polys: array<Poly>;
@group(0) @binding(2) var<storage, read> configs: array<Config>;
// Per configuration: the visible form factor, the lobe's clamped integral E(clip(M⁻¹V)), and
// a status (0 done, 1 an array overflowed, 2 the lobe's horizon crossings do not alternate).
@group(0) @binding(3) var<storage, read_write> results: array<vec4<real>>;
// Per configuration, M⁻¹ of its lobe as three columns (w unused).
@group(0) @binding(4) var<storage, read> lobes: array<vec4<real>>;

struct Edge {
    a: vec3r,
    b: vec3r,
    u: vec3r,
    n: vec3r,
    theta: real,
    proper: bool,
    poly: u32,
    // The middle of the arc (which side of two circles their crossing lies on).
    centre: vec3r,
}

var<private> edges: array<Edge, MAX_EDGES>;
var<private> poly_first: array<u32, MAX_EDGES>;
var<private> poly_end: array<u32, MAX_EDGES>;
var<private> cuts: array<real, MAX_CUTS>;
// Where each cut's point comes from (`cut_point`): the edge's ends, the other polygon's vertex
// on its circle, or the crossing computed the same way for both edges (`crossing`), so that
// V's boundary closes to the bit. A code, not the point: cheap to sort.
var<private> cut_codes: array<u32, MAX_CUTS>;
const CUT_START: u32 = 0xfffffffeu;
const CUT_END: u32 = 0xffffffffu;
var<private> collinear_edges: array<u32, MAX_EDGES>;
var<private> collinear_count: u32;
// The lobe's horizon crossings: azimuth, and 1 for an entry (the boundary comes up), 0 for an
// exit.
// Two clamped sums: 0 the form factor (where the configuration asks for its horizon clip
// here), 1 the lobe.
var<private> crossing_azimuth: array<array<real, MAX_CROSSINGS>, 2>;
var<private> crossing_entry: array<array<u32, MAX_CROSSINGS>, 2>;
var<private> crossing_count: array<u32, 2>;
var<private> clamped_sum: array<real, 2>;
var<private> clamp_overflow: bool;
var<private> lobe_matrix: mat3x3<real>;

ATAN2_DEFINITION

// `v` on the horizon where it lies within EPS_LINE of it: the circle every polygon shares.
fn on_the_horizon(v: vec3r) -> vec3r {
    if v.z != 0.0 && abs(v.z) <= EPS_LINE * length(v) {
        return vec3r(v.x, v.y, 0.0);
    }
    return v;
}

fn make_edge(a0: vec3r, b0: vec3r, poly: u32) -> Edge {
    let a = normalize(on_the_horizon(a0));
    let b = normalize(on_the_horizon(b0));
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
    let m = a + b;
    let lm = length(m);
    if lm > 0.0 {
        e.centre = m / lm;
    } else {
        e.centre = a;
    }
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

// Both ends of the shorter edge (`ei`, `fi` their indices break ties) within EPS_LINE of the
// longer's circle: the shorter's own circle is known only to rounding over its length.
fn is_collinear(e: Edge, ei: u32, f: Edge, fi: u32) -> bool {
    if !(e.proper && f.proper) {
        return false;
    }
    var shorter = e;
    var longer = f;
    if f.theta < e.theta || (f.theta == e.theta && fi < ei) {
        shorter = f;
        longer = e;
    }
    return abs(dot(longer.n, shorter.a)) <= EPS_LINE && abs(dot(longer.n, shorter.b)) <= EPS_LINE;
}

// Where the circles of edges `ei` and `fi` cross, on the arcs' side: ±(n_lo × n_hi) in index
// order, the same point to the bit for both edges (length 0 when the circles coincide).
fn crossing(e: Edge, ei: u32, f: Edge, fi: u32) -> vec3r {
    var lo = e;
    var hi = f;
    if fi < ei {
        lo = f;
        hi = e;
    }
    let x = cross(lo.n, hi.n);
    let l = length(x);
    if l == 0.0 {
        return x;
    }
    if dot(x, lo.centre + hi.centre) >= 0.0 {
        return x / l;
    }
    return -x / l;
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

// Where the arc a → b (one end above, one below) meets the horizon.
fn on_horizon(a: vec3r, b: vec3r) -> vec3r {
    let c = a * abs(b.z) + b * abs(a.z);
    return normalize(vec3r(c.x, c.y, 0.0));
}

fn push_crossing(k: u32, c: vec3r, entry: u32) {
    let n = crossing_count[k];
    if n >= MAX_CROSSINGS {
        clamp_overflow = true;
        return;
    }
    crossing_azimuth[k][n] = atan2r(c.y, c.x);
    crossing_entry[k][n] = entry;
    crossing_count[k] = n + 1u;
}

// A piece a → b of a boundary, kept where z ≥ 0 (`geometry::clamped_integral_of_boundary`);
// its horizon crossings are kept for the closure of sum k.
fn clamped_piece(k: u32, a: vec3r, b: vec3r) {
    let up_a = a.z >= 0.0;
    let up_b = b.z >= 0.0;
    if up_a && up_b {
        clamped_sum[k] += edge_integral(a, b);
    } else if up_a {
        let c = on_horizon(a, b);
        clamped_sum[k] += edge_integral(a, c);
        push_crossing(k, c, 0u);
    } else if up_b {
        let c = on_horizon(a, b);
        clamped_sum[k] += edge_integral(c, b);
        push_crossing(k, c, 1u);
    }
}

// The horizon closes the clipped boundary of sum k: crossings by azimuth, each exit joined to
// the next entry counter-clockwise, whose edge integral is the azimuthal angle between them.
// False when the crossings do not alternate.
fn close_clamped(k: u32) -> bool {
    let n = crossing_count[k];
    if n == 0u {
        return true;
    }
    for (var i = 1u; i < n; i++) {
        let phi = crossing_azimuth[k][i];
        let entry = crossing_entry[k][i];
        var j = i;
        while j > 0u && crossing_azimuth[k][j - 1u] > phi {
            crossing_azimuth[k][j] = crossing_azimuth[k][j - 1u];
            crossing_entry[k][j] = crossing_entry[k][j - 1u];
            j -= 1u;
        }
        crossing_azimuth[k][j] = phi;
        crossing_entry[k][j] = entry;
    }
    var entries = 0u;
    for (var i = 0u; i < n; i++) {
        entries += crossing_entry[k][i];
    }
    if 2u * entries != n {
        return false;
    }
    for (var i = 0u; i < n; i++) {
        if crossing_entry[k][i] == 1u {
            continue;
        }
        let next = (i + 1u) % n;
        if crossing_entry[k][next] != 1u {
            return false;
        }
        var span = crossing_azimuth[k][next] - crossing_azimuth[k][i];
        if span < 0.0 || (span == 0.0 && n == 2u && i + 1u == n) {
            span += TAU;
        }
        clamped_sum[k] += span;
    }
    return true;
}

// The point of cut `code` on edge `ei`: its own end, vertex a (code 4 fi) or b (4 fi + 1) of
// edge fi, or the crossing with edge fi's circle (4 fi + 2).
fn cut_point(e: Edge, ei: u32, code: u32) -> vec3r {
    if code == CUT_START {
        return e.a;
    }
    if code == CUT_END {
        return e.b;
    }
    let fi = code / 4u;
    let f = edges[fi];
    switch code % 4u {
        case 0u: {
            return f.a;
        }
        case 1u: {
            return f.b;
        }
        default: {
            return crossing(e, ei, f, fi);
        }
    }
}

fn add_cut(count: ptr<function, u32>, e: Edge, p: vec3r, code: u32) -> bool {
    let t = param(e, p);
    if t > 0.0 && t < e.theta {
        if *count >= MAX_CUTS {
            return false;
        }
        cuts[*count] = t;
        cut_codes[*count] = code;
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
    crossing_count[0] = 0u;
    crossing_count[1] = 0u;
    clamped_sum[0] = 0.0;
    clamped_sum[1] = 0.0;
    clamp_overflow = false;
    if config.has_lobe != 0u {
        lobe_matrix = mat3x3<real>(
            lobes[3u * ci].xyz,
            lobes[3u * ci + 1u].xyz,
            lobes[3u * ci + 2u].xyz,
        );
    }
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
        cut_codes[0] = CUT_START;
        cuts[1] = e.theta;
        cut_codes[1] = CUT_END;
        count = 2u;
        var ok = true;
        for (var fi = 0u; fi < edge_count; fi++) {
            let f = edges[fi];
            if f.poly == e.poly {
                continue;
            }
            if is_collinear(e, ei, f, fi) {
                collinear_edges[collinear_count] = fi;
                collinear_count += 1u;
                ok = ok && add_cut(&count, e, f.a, 4u * fi);
                ok = ok && add_cut(&count, e, f.b, 4u * fi + 1u);
                continue;
            }
            let da = dot(e.n, f.a);
            let db = dot(e.n, f.b);
            if abs(da) <= EPS_LINE {
                ok = ok && add_cut(&count, e, f.a, 4u * fi);
            }
            if abs(db) <= EPS_LINE {
                ok = ok && add_cut(&count, e, f.b, 4u * fi + 1u);
            }
            // An end on the circle is the one point where the arc meets it.
            if f.proper && abs(da) > EPS_LINE && abs(db) > EPS_LINE
                && ((da > 0.0 && db < 0.0) || (da < 0.0 && db > 0.0)) {
                let x = crossing(e, ei, f, fi);
                if length(x) > 0.0 {
                    ok = ok && add_cut(&count, e, x, 4u * fi + 2u);
                }
            }
        }
        if !ok {
            results[ci] = vec4<real>(0.0, 0.0, 1.0, 0.0);
            return;
        }
        for (var i = 1u; i < count; i++) {
            let t = cuts[i];
            let c = cut_codes[i];
            var j = i;
            while j > 0u && cuts[j - 1u] > t {
                cuts[j] = cuts[j - 1u];
                cut_codes[j] = cut_codes[j - 1u];
                j -= 1u;
            }
            cuts[j] = t;
            cut_codes[j] = c;
        }
        // Cuts closer than the resolution are one (θ, the last, over a cut just before it).
        var kept = 0u;
        for (var i = 1u; i < count; i++) {
            let last = i + 1u == count;
            if cuts[i] - cuts[kept] > CUT_RESOLUTION || (last && kept == 0u) {
                kept += 1u;
            } else if !last {
                continue;
            }
            cuts[kept] = cuts[i];
            cut_codes[kept] = cut_codes[i];
        }
        count = kept + 1u;
        // Each sub-arc's own term: sub-arcs of one great circle add.
        for (var j = 0u; j + 1u < count; j++) {
            let t0 = cuts[j];
            let t1 = cuts[j + 1u];
            if t1 <= t0 {
                continue;
            }
            let dir = decide(e, point_at(e, 0.5 * (t0 + t1)), config.poly_count);
            if dir != 0 {
                var start = cut_point(e, ei, cut_codes[j]);
                var end = cut_point(e, ei, cut_codes[j + 1u]);
                if dir < 0 {
                    let s = start;
                    start = end;
                    end = s;
                }
                if config.clip_here != 0u {
                    clamped_piece(0u, start, end);
                } else {
                    sum += edge_integral(start, end);
                }
                if config.has_lobe != 0u {
                    clamped_piece(1u, normalize(lobe_matrix * start), normalize(lobe_matrix * end));
                }
            }
        }
    }
    var status: real = 0.0;
    if clamp_overflow {
        status = 1.0;
    }
    if config.clip_here != 0u {
        if !close_clamped(0u) {
            status = 2.0;
        }
        sum = clamped_sum[0];
    }
    if config.has_lobe != 0u && !close_clamped(1u) {
        status = 2.0;
    }
    results[ci] = vec4<real>(sum / TAU, clamped_sum[1] / TAU, status, 0.0);
}
