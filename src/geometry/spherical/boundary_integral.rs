//! The visible integral from its boundary: a second exact way to integrate over
//! `V = L ∖ (O_1 ∪ … ∪ O_n)` beside the Greiner–Hormann set difference, which finds V's
//! oriented boundary edge by edge without building V (docs/boundary-integral.md).
//!
//! Every integral the shader takes over V is a sum of edge terms over V's boundary (Stokes:
//! 000 Eq. 2 written edge by edge, 001 Eq. 3.14; the same after the LTC transform M⁻¹, which
//! maps arcs to arcs). The boundary
//! of V consists of
//!
//! - (a) the pieces of L's edges that lie outside every occluder, in L's orientation, and
//! - (b) the pieces of each occluder's edges that lie inside L and outside every other
//!   occluder, reversed (V lies on the occluder's outside, i.e. its right).
//!
//! Both kinds come from one rule applied to every edge of every polygon: cut the edge where any
//! other polygon's boundary meets its great circle, and for each sub-arc decide whether the
//! region just to its left and just to its right belongs to V. A sub-arc with V on its left
//! only is a boundary piece in the edge's direction, with V on its right only a piece in the
//! reverse direction, otherwise it is not part of the boundary. The side of a polygon is
//! decided at the sub-arc's midpoint by its winding number, in which an edge lying on the
//! sub-arc's great circle (a collinear contact, decided with [`EPS_LINE`]) counts as half a
//! turn to the side it bounds. A sub-arc on the boundary of several polygons is emitted once,
//! by the first of them (the light, then the occluders in order).
//!
//! Nothing is allocated once the scratch buffers have grown. Cost: for each edge, O(total
//! edges) to find its cuts and O(edges of a polygon) per sub-arc and polygon for the sides;
//! polygons whose bounding cap misses the edge's are skipped.

use crate::geometry::{EPS_LINE, SphericalPolygon};
use crate::math::angle_between;
use glam::DVec3;
use std::f64::consts::{FRAC_PI_2, PI, TAU};

/// Which polygon a boundary piece lies on.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum PieceSource {
    /// An edge of the light.
    Light,
    /// An edge of occluder `i` (its index in the order the occluders were given).
    Occluder(usize),
}

/// One piece of V's oriented boundary: the sub-arc `t0..t1` (angles in radians from the start
/// of the source edge, `0 ≤ t0 < t1 ≤` the edge's angle) of edge `edge` of loop `loop_index`
/// of its source polygon, traversed from `start` to `end` (V on the left). `reversed` is set
/// when that is against the source edge's direction (occluder pieces); then `start` is the
/// point at `t1`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct BoundaryPiece {
    pub source: PieceSource,
    pub loop_index: usize,
    pub edge: usize,
    pub t0: f64,
    pub t1: f64,
    pub reversed: bool,
    pub start: DVec3,
    pub end: DVec3,
}

/// An edge of one of the polygons, with its great circle's frame: `p(t) = a cos t + u sin t`
/// for `t ∈ [0, theta]`, `n = a × u` its unit normal (the polygon's side is `n · p > 0`).
#[derive(Clone, Copy, Debug)]
struct Edge {
    a: DVec3,
    b: DVec3,
    u: DVec3,
    n: DVec3,
    theta: f64,
    /// False for a zero-length edge or one between antipodal points (no great circle).
    proper: bool,
    /// Bounding cap of the arc: centre and angular radius.
    centre: DVec3,
    radius: f64,
    poly: u32,
    loop_index: u32,
    index: u32,
    /// Its place among all the edges.
    id: u32,
}

impl Edge {
    fn new(a: DVec3, b: DVec3, poly: u32, loop_index: u32, index: u32) -> Edge {
        let (a, b) = (
            a.try_normalize().unwrap_or(DVec3::Z),
            b.try_normalize().unwrap_or(DVec3::Z),
        );
        // a × b as ½ (a + b) × (b − a): relative precision for short edges.
        let w = (a + b).cross(b - a) * 0.5;
        let s = w.length();
        let c = a.dot(b);
        let proper = s > 0.0 && w.is_finite();
        let n = if proper { w / s } else { DVec3::Z };
        let u = n.cross(a);
        let theta = if proper { s.atan2(c) } else { 0.0 };
        let mid = (a + b).try_normalize().unwrap_or(a);
        let radius = if proper { 0.5 * theta } else { 0.0 };
        Edge {
            a,
            b,
            u,
            n,
            theta,
            proper,
            centre: mid,
            radius,
            poly,
            loop_index,
            index,
            id: 0,
        }
    }

    #[inline]
    fn param(&self, p: DVec3) -> f64 {
        p.dot(self.u).atan2(p.dot(self.a))
    }

    #[inline]
    fn point(&self, t: f64) -> DVec3 {
        if t <= 0.0 {
            self.a
        } else if t >= self.theta {
            self.b
        } else {
            self.a * t.cos() + self.u * t.sin()
        }
    }

    /// Whether `p` (on this edge's circle) lies strictly inside the arc.
    #[inline]
    fn contains_on_circle(&self, p: DVec3) -> bool {
        let t = self.param(p);
        t > 0.0 && t < self.theta
    }
}

/// The edges of one polygon and its bounding cap.
#[derive(Clone, Copy, Debug)]
struct Poly {
    /// Where its pieces come from (occluders of no area are not pushed: the index is the one
    /// the caller gave).
    source: PieceSource,
    first: u32,
    end: u32,
    centre: DVec3,
    radius: f64,
    /// The cap holds the whole region (radius below π/2): outside it, the winding number is 0.
    bounded: bool,
    /// Given as a set of arcs ([`OccluderRegion::Arcs`]), not loops: its own edges may cross and
    /// cover each other, so they cut each other and its own sides are winding numbers too.
    layered: bool,
}

/// An occluder of [`boundary_pieces`]: a polygon, or a set of oriented arcs in any order — a
/// mesh's contour edges at the point, unchained — whose region is where they wind once or more
/// (a closed mesh's front faces wind once per layer). Sides are winding numbers and cuts are per
/// edge, so no loop is needed: what a GPU wants (docs/gpu.md).
#[derive(Clone, Copy, Debug)]
pub enum OccluderRegion<'a> {
    Polygon(&'a SphericalPolygon),
    Arcs(&'a [(DVec3, DVec3)]),
}

impl<'a> From<&'a SphericalPolygon> for OccluderRegion<'a> {
    fn from(p: &'a SphericalPolygon) -> Self {
        OccluderRegion::Polygon(p)
    }
}

/// Reusable buffers for [`boundary_pieces`]: once grown, the functions of this module do not
/// allocate.
#[derive(Clone, Debug, Default)]
pub struct BoundaryScratch {
    edges: Vec<Edge>,
    polys: Vec<Poly>,
    /// Cut parameters along the edge being cut, with the point there: the edge's own ends, the
    /// other polygon's vertex that lies on its circle, or the crossing of the two circles
    /// computed once for both edges ([`crossing`]), so that the pieces meeting there share the
    /// point to the bit and the boundary closes.
    cuts: Vec<(f64, DVec3)>,
    /// Edges collinear with the edge being cut.
    collinear: Vec<u32>,
    /// Per polygon, for the edge being cut: whether it cut the edge (or has an edge on its
    /// circle), and if not, its sides along the whole edge once known.
    touches: Vec<bool>,
    constant: Vec<Option<(bool, bool)>>,
}

/// Whether edges `e` and `f` lie on one great circle: both ends of the shorter within
/// [`EPS_LINE`] of the longer's circle, and so all of it (symmetric, so that both edges agree).
/// The shorter edge's own circle is not a reference: its normal is known to rounding over its
/// length (a window's clip of a light edge 1e-6 long tilts it by 1e-10), and the longer edge's
/// far end would miss it.
#[inline]
fn collinear(e: &Edge, f: &Edge) -> bool {
    let key = |x: &Edge| (x.theta, x.poly, x.loop_index, x.index);
    let (short, long) = if key(f) < key(e) { (f, e) } else { (e, f) };
    e.proper
        && f.proper
        && long.n.dot(short.a).abs() <= EPS_LINE
        && long.n.dot(short.b).abs() <= EPS_LINE
}

/// The point where the circles of edges `e` (index `ei`) and `f` (index `fi`) cross, on the side
/// of the two arcs: `±(n_lo × n_hi)` with the edges taken in the order of their indices, so that
/// both edges get the same point to the bit (computed from each edge's ends, the two points
/// differ by rounding over the sine of the angle between the circles, and the sliver between
/// them leaves the boundary open by an edge term of that length).
#[inline]
fn crossing(e: &Edge, ei: usize, f: &Edge, fi: usize) -> Option<DVec3> {
    let (lo, hi) = if ei < fi { (e, f) } else { (f, e) };
    let x = lo.n.cross(hi.n).try_normalize()?;
    // The sum of the two arcs' middles, the same in either order.
    Some(if x.dot(lo.centre + hi.centre) >= 0.0 {
        x
    } else {
        -x
    })
}

/// `v` on the horizon where it lies within [`EPS_LINE`] of it. The horizon is the one circle
/// all the polygons share: the clip puts the light's and the occluders' crossings on it, and a
/// face in the shading point's tangent plane lies on it to rounding (z of 1e-17). Left apart,
/// the two circles are collinear by the tolerance but not to a third edge that crosses them at a
/// grazing angle: its two cuts fall 1e-10 apart, and the sub-arc between them, decided by
/// rounding, has the edge term of an arc on the horizon (docs/boundary-integral.md).
#[inline]
fn on_horizon(v: DVec3) -> DVec3 {
    if v.z != 0.0 && v.z.abs() <= EPS_LINE * v.length() {
        DVec3::new(v.x, v.y, 0.0)
    } else {
        v
    }
}

/// Cut parameters (radians) closer than this are one cut: a few ulps of the unit vectors'
/// coordinates, the resolution of a point's parameter on an edge.
const CUT_RESOLUTION: f64 = 8.0 * f64::EPSILON;

/// Whether the caps of `e` and of polygon `p` may meet (with slack for rounding).
#[inline]
fn may_meet(e: &Edge, p: &Poly) -> bool {
    if !p.bounded {
        return true;
    }
    let d = angle_between(e.centre, p.centre);
    d <= e.radius + p.radius + 1e-9
}

impl BoundaryScratch {
    pub fn new() -> Self {
        Self::default()
    }

    fn push_polygon(&mut self, poly: &SphericalPolygon, source: PieceSource) {
        let pi = self.polys.len() as u32;
        let first = self.edges.len() as u32;
        for (li, lp) in poly.loops().enumerate() {
            let n = lp.len();
            if n < 2 {
                continue;
            }
            for k in 0..n {
                self.push_edge(lp[k], lp[(k + 1) % n], pi, li as u32, k as u32);
            }
        }
        self.close_polygon(source, first, false);
    }

    fn push_arcs(&mut self, arcs: &[(DVec3, DVec3)], source: PieceSource) {
        let pi = self.polys.len() as u32;
        let first = self.edges.len() as u32;
        for (k, &(a, b)) in arcs.iter().enumerate() {
            self.push_edge(a, b, pi, 0, k as u32);
        }
        self.close_polygon(source, first, true);
    }

    fn push_edge(&mut self, a: DVec3, b: DVec3, poly: u32, loop_index: u32, index: u32) {
        let mut e = Edge::new(on_horizon(a), on_horizon(b), poly, loop_index, index);
        e.id = self.edges.len() as u32;
        self.edges.push(e);
    }

    /// The polygon of the edges from `first` on: its bounding cap.
    fn close_polygon(&mut self, source: PieceSource, first: u32, layered: bool) {
        let end = self.edges.len() as u32;
        let sum: DVec3 = self.edges[first as usize..end as usize]
            .iter()
            .map(|e| e.a)
            .sum();
        let centre = sum.try_normalize().unwrap_or(DVec3::Z);
        let mut radius: f64 = 0.0;
        for e in &self.edges[first as usize..end as usize] {
            radius = radius.max(angle_between(centre, e.a));
        }
        // Arcs between points of a cap narrower than a hemisphere stay in it.
        let bounded = sum.length() > 1e-6 && radius < FRAC_PI_2 - 1e-6;
        self.polys.push(Poly {
            source,
            first,
            end,
            centre,
            radius,
            bounded,
            layered,
        });
    }

    /// The cuts of edge `ei` into `self.cuts` (sorted by parameter, with 0 and θ), and its
    /// collinear partners into `self.collinear`.
    fn cut(&mut self, ei: usize) {
        let e = self.edges[ei];
        self.cuts.clear();
        self.collinear.clear();
        self.cuts.push((0.0, e.a));
        self.cuts.push((e.theta, e.b));
        self.touches.clear();
        self.touches.resize(self.polys.len(), false);
        self.constant.clear();
        self.constant.resize(self.polys.len(), None);
        let add = |cuts: &mut Vec<(f64, DVec3)>, p: DVec3| {
            let t = e.param(p);
            if t > 0.0 && t < e.theta {
                cuts.push((t, p));
            }
        };
        for (pi, p) in self.polys.iter().enumerate() {
            if (pi == e.poly as usize && !p.layered) || !may_meet(&e, p) {
                continue;
            }
            let (cuts_before, collinear_before) = (self.cuts.len(), self.collinear.len());
            for fi in p.first..p.end {
                if fi as usize == ei {
                    continue;
                }
                let f = &self.edges[fi as usize];
                if collinear(&e, f) {
                    self.collinear.push(fi);
                    add(&mut self.cuts, f.a);
                    add(&mut self.cuts, f.b);
                    continue;
                }
                let (da, db) = (e.n.dot(f.a), e.n.dot(f.b));
                // Endpoints on (or near) the circle are cuts, at their feet, and the pieces end
                // at the vertex itself (extra cuts are harmless, a missing one is not).
                if da.abs() <= EPS_LINE {
                    add(&mut self.cuts, f.a);
                }
                if db.abs() <= EPS_LINE {
                    add(&mut self.cuts, f.b);
                }
                // An arc shorter than π meets another circle at most once: at an end within
                // the tolerance, that end is the point (a crossing computed from an end off
                // the circle by rounding would be a second cut beside it, and the sub-arc
                // between the two would be decided by rounding).
                if f.proper
                    && da.abs() > EPS_LINE
                    && db.abs() > EPS_LINE
                    && (da > 0.0) != (db > 0.0)
                    && let Some(x) = crossing(&e, ei, f, fi as usize)
                {
                    add(&mut self.cuts, x);
                }
            }
            self.touches[pi] =
                self.cuts.len() > cuts_before || self.collinear.len() > collinear_before;
        }
        self.cuts.sort_unstable_by(|x, y| x.0.total_cmp(&y.0));
        // Cuts closer than rounding are one (the first; an end of the edge over a cut beside
        // it): a sub-arc of a few ulps is two copies of one point, and its side, taken at a
        // point on a vertex, is rounding.
        let n = self.cuts.len();
        let mut kept = 0;
        for i in 1..n {
            let c = self.cuts[i];
            let last = i == n - 1;
            if c.0 - self.cuts[kept].0 > CUT_RESOLUTION || (last && kept == 0) {
                kept += 1;
            } else if !last {
                continue;
            }
            // (θ, the last, takes the place of a cut just before it.)
            self.cuts[kept] = c;
        }
        self.cuts.truncate(kept + 1);
    }

    /// The sides of polygon `pi` at the point `m` of edge `e`'s circle: (left inside, right
    /// inside), from the winding number in which the collinear edges count half a turn.
    fn sides(&mut self, e: &Edge, pi: usize, m: DVec3) -> (bool, bool) {
        if !self.touches[pi] {
            // No boundary of the polygon meets the edge: one side, the same along all of it,
            // taken at the edge's middle, away from its ends (a vertex of the polygon may
            // coincide with one, where the winding is rounding; the first sub-arc can be a
            // sliver at such an end).
            if let Some(s) = self.constant[pi] {
                return s;
            }
            let s = self.winding_sides(e, pi, e.point(0.5 * e.theta));
            self.constant[pi] = Some(s);
            return s;
        }
        self.winding_sides(e, pi, m)
    }

    fn winding_sides(&self, e: &Edge, pi: usize, m: DVec3) -> (bool, bool) {
        let p = &self.polys[pi];
        if !may_meet(e, p) || (p.bounded && angle_between(m, p.centre) > p.radius + 1e-9) {
            return (false, false);
        }
        let mut w = 0.0;
        // A layered polygon's sides at its own edge: the edge is half a turn to its left.
        let mut half_turns = i32::from(pi == e.poly as usize);
        for fi in p.first..p.end {
            let f = &self.edges[fi as usize];
            if fi == e.id {
                continue;
            }
            if self.collinear.contains(&fi) {
                if f.contains_on_circle(m) {
                    half_turns += if f.n.dot(e.n) > 0.0 { 1 } else { -1 };
                }
                continue;
            }
            let pa = f.a - m * m.dot(f.a);
            let pb = f.b - m * m.dot(f.b);
            w += m.dot(pa.cross(pb)).atan2(pa.dot(pb));
        }
        let h = PI * f64::from(half_turns);
        ((w + h) / TAU > 0.5, (w - h) / TAU > 0.5)
    }

    /// Whether the point `m` of edge `e` lies on a collinear edge of a polygon before `e`'s own
    /// (which then owns the piece).
    fn owned_earlier(&self, e: &Edge, m: DVec3) -> bool {
        self.collinear.iter().any(|&fi| {
            let f = &self.edges[fi as usize];
            f.poly < e.poly && f.contains_on_circle(m)
        })
    }

    /// What the sub-arc at `m` of edge `e` is: +1 a piece along e, −1 against it, 0 none.
    fn decide(&mut self, e: &Edge, m: DVec3) -> i8 {
        if self.owned_earlier(e, m) {
            return 0;
        }
        let own = e.poly as usize;
        // Membership in V of the left and right sides: in the light, in no occluder.
        let (mut left, mut right) = if own == 0 {
            (true, false)
        } else {
            self.sides(e, 0, m)
        };
        if own != 0 {
            if self.polys[own].layered {
                // Other layers of its own may cover either side.
                let (l, r) = self.sides(e, own, m);
                left &= !l;
                right &= !r;
            } else {
                // Inside its own occluder on the left.
                left = false;
            }
        }
        for pi in 1..self.polys.len() {
            if !left && !right {
                break;
            }
            if pi == own {
                continue;
            }
            let (l, r) = self.sides(e, pi, m);
            left &= !l;
            right &= !r;
        }
        match (left, right) {
            (true, false) => 1,
            (false, true) => -1,
            _ => 0,
        }
    }
}

/// Calls `visit` with every piece of the oriented boundary of `V = light ∖ ∪ occluders`.
///
/// All polygons are regions of the unit sphere in one frame, filled loops counter-clockwise
/// seen from outside (holes clockwise), loops of one polygon not crossing each other, arcs
/// shorter than π: the conventions of [`SphericalPolygon`]. The light is clipped to the upper
/// hemisphere (`clip_to_horizon`), and so are the occluders, so that their boundary includes
/// the horizon arcs that close them; an occluder horizon arc on the light's horizon arc is a
/// collinear contact in the same direction and is dropped (docs/boundary-integral.md). Pieces
/// of one edge are visited in the order of their parameter; light edges first, then each
/// occluder's. Degenerate edges (zero length, antipodal ends) give no piece.
pub fn boundary_pieces<'a, O: Into<OccluderRegion<'a>>>(
    light: &SphericalPolygon,
    occluders: impl IntoIterator<Item = O>,
    scratch: &mut BoundaryScratch,
    mut visit: impl FnMut(&BoundaryPiece),
) {
    scratch.edges.clear();
    scratch.polys.clear();
    scratch.push_polygon(light, PieceSource::Light);
    for (i, o) in occluders.into_iter().enumerate() {
        match o.into() {
            // An occluder of no area (a face seen edge-on: every vertex within `EPS_LINE` of
            // one great circle) hides nothing; its edges, on top of each other, would leave
            // their pairing to rounding.
            OccluderRegion::Polygon(o) => {
                if !lies_on_one_circle(o) {
                    scratch.push_polygon(o, PieceSource::Occluder(i));
                }
            }
            OccluderRegion::Arcs(arcs) => scratch.push_arcs(arcs, PieceSource::Occluder(i)),
        }
    }
    let light_poly = scratch.polys[0];
    for ei in 0..scratch.edges.len() {
        let e = scratch.edges[ei];
        if !e.proper {
            continue;
        }
        // An occluder edge away from the light bounds nothing of V.
        if e.poly != 0 && !may_meet(&e, &light_poly) {
            continue;
        }
        scratch.cut(ei);
        let mut run: Option<(f64, DVec3, i8)> = None;
        let k = scratch.cuts.len();
        for j in 0..k {
            let dir = if j + 1 < k {
                let (t0, t1) = (scratch.cuts[j].0, scratch.cuts[j + 1].0);
                scratch.decide(&e, e.point(0.5 * (t0 + t1)))
            } else {
                0
            };
            let (t, p1) = scratch.cuts[j];
            match run {
                Some((_, _, d)) if d == dir => {}
                _ => {
                    if let Some((t0, p0, d)) = run.take()
                        && d != 0
                    {
                        let source = scratch.polys[e.poly as usize].source;
                        let (start, end) = if d > 0 { (p0, p1) } else { (p1, p0) };
                        visit(&BoundaryPiece {
                            source,
                            loop_index: e.loop_index as usize,
                            edge: e.index as usize,
                            t0,
                            t1: t,
                            reversed: d < 0,
                            start,
                            end,
                        });
                    }
                    run = Some((t, p1, dir));
                }
            }
        }
    }
}

/// Whether every vertex of `poly` lies within [`EPS_LINE`] of the great circle through its
/// first vertex and the vertex farthest from it (a region of zero area); true for an empty
/// polygon.
fn lies_on_one_circle(poly: &SphericalPolygon) -> bool {
    let vs = poly.vertices();
    let Some(&first) = vs.first() else {
        return true;
    };
    let far = vs
        .iter()
        .copied()
        .min_by(|x, y| first.dot(*x).total_cmp(&first.dot(*y)))
        .unwrap_or(first);
    let Some(n) = first.cross(far).try_normalize() else {
        // All at one point, or a pair of antipodes: a circle only when all lie on them.
        return vs.iter().all(|v| v.cross(first).length() <= EPS_LINE);
    };
    vs.iter().all(|v| n.dot(*v).abs() <= EPS_LINE)
}

/// `Σ term(start, end)` over the pieces of [`boundary_pieces`]: the integral over V of any
/// quantity whose integral over a region is a sum of edge terms. With `term =
/// ltc::edge_integral` it is `2π` times `ltc::form_factor` of V in the frame given; for a lobe,
/// `|a, b| edge_integral(M⁻¹a, M⁻¹b)` gives the integral of the *unclamped* cosine over M⁻¹V
/// (the shader clips M⁻¹V to the horizon again; this sum does not).
pub fn visible_integral_from_boundary<'a, O: Into<OccluderRegion<'a>>>(
    light: &SphericalPolygon,
    occluders: impl IntoIterator<Item = O>,
    scratch: &mut BoundaryScratch,
    mut term: impl FnMut(DVec3, DVec3) -> f64,
) -> f64 {
    let mut sum = 0.0;
    boundary_pieces(light, occluders, scratch, |p| sum += term(p.start, p.end));
    sum
}

/// `Σ term` over the boundary of `R ∩ {z ≥ 0}`, for a region R given by its oriented boundary
/// `arcs` (R on the left; each arc shorter than π): the clamped integral the shader takes of the
/// LTC lobe, `E(clip(M⁻¹V))`, from the boundary pieces of V mapped by M⁻¹ (docs/boundary-integral.md,
/// "The horizon of the lobe").
///
/// Each arc is kept where `z ≥ 0`; an arc that crosses the horizon is cut at its crossing
/// `c ∝ a |b_z| + b |a_z|`, an *exit* where the arc goes down, an *entry* where it comes up.
/// The horizon closes the clipped boundary: seen from above (+z), R ∩ {z ≥ 0} lies left of the
/// horizon walked counter-clockwise, so each exit is joined to the next crossing in increasing
/// azimuth `atan2(c_y, c_x)`, which must be an entry, by horizon arcs (split below π; their
/// edge integral is not zero). `None` when the crossings do not alternate (a boundary that is
/// not closed, or rounding at a tangency): the caller takes the polygon's path instead.
pub fn clamped_integral_of_boundary(
    arcs: impl IntoIterator<Item = (DVec3, DVec3)>,
    crossings: &mut Vec<(f64, bool, DVec3)>,
    mut term: impl FnMut(DVec3, DVec3) -> f64,
) -> Option<f64> {
    crossings.clear();
    let mut sum = 0.0;
    let on_horizon = |a: DVec3, b: DVec3| {
        let c = a * b.z.abs() + b * a.z.abs();
        DVec3::new(c.x, c.y, 0.0).try_normalize().unwrap_or(a)
    };
    for (a, b) in arcs {
        match (a.z >= 0.0, b.z >= 0.0) {
            (true, true) => sum += term(a, b),
            (false, false) => {}
            (true, false) => {
                let c = on_horizon(a, b);
                sum += term(a, c);
                crossings.push((c.y.atan2(c.x), false, c));
            }
            (false, true) => {
                let c = on_horizon(a, b);
                sum += term(c, b);
                crossings.push((c.y.atan2(c.x), true, c));
            }
        }
    }
    if crossings.is_empty() {
        return Some(sum);
    }
    crossings.sort_by(|x, y| x.0.total_cmp(&y.0));
    let n = crossings.len();
    let entries = crossings.iter().filter(|c| c.1).count();
    if 2 * entries != n {
        return None;
    }
    for i in 0..n {
        let (phi, entry, from) = crossings[i];
        if entry {
            continue;
        }
        let (next_phi, next_entry, to) = crossings[(i + 1) % n];
        if !next_entry {
            return None;
        }
        let mut span = next_phi - phi;
        if span < 0.0 || (span == 0.0 && n == 2 && i + 1 == n) {
            span += TAU;
        }
        // Horizon arcs below π each: at most four quarter turns.
        let pieces = (span / FRAC_PI_2).ceil().max(1.0) as usize;
        let mut prev = from;
        for k in 1..=pieces {
            let p = if k == pieces {
                to
            } else {
                let t = phi + span * k as f64 / pieces as f64;
                DVec3::new(t.cos(), t.sin(), 0.0)
            };
            sum += term(prev, p);
            prev = p;
        }
    }
    Some(sum)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geometry::test_util::{contains, random_star_loop};
    use crate::geometry::{
        HorizonScratch, PlanarPolygon, ProjectionPlane, SetDifference, clip_to_horizon,
    };
    use crate::ltc::{edge_integral, form_factor};
    use crate::math::{Frame, Pcg32};

    /// `E(V)` from the boundary pieces, in the shading frame.
    fn boundary_ff(light: &SphericalPolygon, occ: &[SphericalPolygon]) -> f64 {
        let mut s = BoundaryScratch::new();
        visible_integral_from_boundary(light, occ, &mut s, edge_integral) / TAU
    }

    /// `E(V)` by the renderer's path: Greiner–Hormann, one occluder at a time, in the
    /// projection plane of Alg. 1, then `form_factor`. `None` when a subtraction reports an
    /// inconsistent traversal.
    fn gh_ff(light: &SphericalPolygon, occ: &[SphericalPolygon]) -> Option<f64> {
        let plane = ProjectionPlane::NORMAL;
        let mut v = PlanarPolygon::new();
        plane.project(light, &mut v);
        let (mut clip, mut out) = (PlanarPolygon::new(), PlanarPolygon::new());
        let mut sd = SetDifference::new();
        for o in occ {
            if v.is_empty() {
                break;
            }
            plane.project(o, &mut clip);
            sd.subtract(&v, &clip, &mut out, None);
            if sd.last_bound_crossed() || !sd.last_traversal_consistent() {
                return None;
            }
            std::mem::swap(&mut v, &mut out);
        }
        let mut sph = SphericalPolygon::new();
        plane.reproject(&v, &mut sph);
        Some(form_factor(sph.loops()))
    }

    /// Cosine-weighted Monte Carlo estimate of `E(V)` and its standard error, containment by
    /// crossing parity toward −z (every polygon lies above the horizon).
    fn mc_ff(
        light: &SphericalPolygon,
        occ: &[SphericalPolygon],
        n: usize,
        rng: &mut Pcg32,
    ) -> (f64, f64) {
        let mut hits = 0usize;
        for _ in 0..n {
            let (r1, r2) = (rng.next_f64(), rng.next_f64());
            let (r, phi) = (r1.sqrt(), TAU * r2);
            let d = DVec3::new(r * phi.cos(), r * phi.sin(), (1.0 - r1).max(0.0).sqrt());
            if contains(light, d, -DVec3::Z) && !occ.iter().any(|o| contains(o, d, -DVec3::Z)) {
                hits += 1;
            }
        }
        let p = hits as f64 / n as f64;
        (p, (p * (1.0 - p) / n as f64).sqrt().max(1.0 / n as f64))
    }

    fn clipped(p: &SphericalPolygon) -> SphericalPolygon {
        let mut out = SphericalPolygon::new();
        clip_to_horizon(p, &mut out, &mut HorizonScratch::default());
        out
    }

    fn poly(verts: &[DVec3]) -> SphericalPolygon {
        let mut p = SphericalPolygon::new();
        p.push_loop(verts.iter().map(|v| v.normalize()));
        p
    }

    /// A regular k-gon of angular radius `atan(r)` about `centre` (convex, counter-clockwise).
    fn regular(centre: DVec3, r: f64, k: usize, turn: f64) -> SphericalPolygon {
        let f = Frame::from_z(centre);
        let mut p = SphericalPolygon::new();
        p.push_loop((0..k).map(|j| {
            let a = turn + j as f64 * TAU / k as f64;
            f.to_world(DVec3::new(r * a.cos(), r * a.sin(), 1.0).normalize())
        }));
        p
    }

    /// A direction at elevation `el` (radians above the horizon) and azimuth `az`.
    fn dir(el: f64, az: f64) -> DVec3 {
        DVec3::new(el.cos() * az.cos(), el.cos() * az.sin(), el.sin())
    }

    /// A random configuration: a light (star-shaped, often non-convex) and one to four
    /// occluders (star-shaped or convex) around nearby directions, all clipped to the horizon;
    /// many reach below it.
    fn random_config(rng: &mut Pcg32) -> (SphericalPolygon, Vec<SphericalPolygon>) {
        let el = rng.range(0.05, 1.5);
        let az = rng.range(0.0, TAU);
        let c = dir(el, az);
        let mut light = SphericalPolygon::new();
        let n = 3 + (rng.next_f64() * 6.0) as usize;
        random_star_loop(&mut light, &Frame::from_z(c), n, rng.range(0.2, 1.2), rng);
        let light = clipped(&light);
        let count = 1 + (rng.next_f64() * 4.0) as usize;
        let mut occ = Vec::new();
        for _ in 0..count {
            let oc = dir(
                (el + rng.range(-0.5, 0.5)).clamp(-0.3, 1.5),
                az + rng.range(-0.6, 0.6),
            );
            let o = if rng.next_f64() < 0.4 {
                let k = 3 + (rng.next_f64() * 5.0) as usize;
                regular(oc, rng.range(0.1, 0.8), k, rng.range(0.0, TAU))
            } else {
                let mut o = SphericalPolygon::new();
                let k = 3 + (rng.next_f64() * 8.0) as usize;
                random_star_loop(&mut o, &Frame::from_z(oc), k, rng.range(0.1, 0.9), rng);
                o
            };
            let o = clipped(&o);
            if !o.is_empty() {
                occ.push(o);
            }
        }
        (light, occ)
    }

    fn rel_err(a: f64, reference: f64) -> f64 {
        (a - reference).abs() / reference.abs().max(1e-3)
    }

    /// Oracle: the Greiner–Hormann path (`SetDifference::subtract` per occluder, then
    /// `form_factor`) on 3000 seeded random configurations: convex and non-convex occluders,
    /// one to four of them, lights and occluders crossing the horizon. Agreement to 1e-10
    /// relative (absolute below E = 1e-3).
    #[test]
    fn agrees_with_greiner_hormann_on_random_configurations() {
        let mut rng = Pcg32::new(2021, 7);
        let (mut worst, mut compared, mut skipped) = (0.0f64, 0, 0);
        let (mut partial, mut hidden, mut horizon) = (0, 0, 0);
        for case in 0..3000 {
            let (light, occ) = random_config(&mut rng);
            let full = form_factor(light.loops());
            let Some(gh) = gh_ff(&light, &occ) else {
                skipped += 1;
                continue;
            };
            let b = boundary_ff(&light, &occ);
            let err = rel_err(b, gh);
            assert!(err < 1e-10, "case {case}: boundary {b} GH {gh} ({err:e})");
            worst = worst.max(err);
            compared += 1;
            if gh.abs() < 1e-12 {
                hidden += 1;
            } else if (gh - full).abs() > 1e-6 {
                partial += 1;
            }
            if occ.iter().any(|o| o.vertices().iter().any(|v| v.z == 0.0)) {
                horizon += 1;
            }
        }
        println!(
            "random: {compared} compared ({partial} partly shadowed, {hidden} hidden, \
             {horizon} with an occluder cut by the horizon), {skipped} skipped, \
             max rel diff {worst:e}"
        );
        assert!(skipped < 30, "{skipped} GH failures");
        assert!(partial > compared / 2 && horizon > compared / 10);
    }

    /// Oracle: Monte Carlo with cosine-weighted directions and a containment test that uses
    /// nothing of this module (crossing parity), on a few random configurations: within five
    /// standard errors.
    /// `E(clip(M⁻¹V))` by the renderer's path (Greiner–Hormann's V, mapped, clipped to the
    /// horizon, `form_factor`) against the boundary's (`clamped_integral_of_boundary` of the
    /// pieces mapped by M⁻¹), with LTC matrices of the embedded table at grazing and steep
    /// views, whose images of V cross the horizon.
    #[test]
    fn the_lobe_from_the_boundary_agrees_with_greiner_hormann() {
        let table = crate::ltc::LtcTable::embedded();
        let mut rng = Pcg32::new(41, 5);
        let (mut checked, mut crossing) = (0, 0);
        let mut scratch = BoundaryScratch::new();
        let mut crossings = Vec::new();
        for case in 0..2000 {
            let (light, occ) = random_config(&mut rng);
            let entry = table.lookup(rng.range(0.02, 1.0), rng.range(0.05, 1.0));
            let map = |w: DVec3| (entry.m_inv * w).normalize();
            // The renderer's path.
            let plane = ProjectionPlane::NORMAL;
            let mut v = PlanarPolygon::new();
            plane.project(&light, &mut v);
            let (mut clip, mut out) = (PlanarPolygon::new(), PlanarPolygon::new());
            let mut sd = SetDifference::new();
            let mut ok = true;
            for o in &occ {
                if v.is_empty() {
                    break;
                }
                plane.project(o, &mut clip);
                sd.subtract(&v, &clip, &mut out, None);
                ok &= !sd.last_bound_crossed() && sd.last_traversal_consistent();
                std::mem::swap(&mut v, &mut out);
            }
            if !ok {
                continue;
            }
            let mut sph = SphericalPolygon::new();
            plane.reproject(&v, &mut sph);
            sph.map_vertices(map);
            let gh = form_factor(clipped(&sph).loops());
            // The boundary's.
            let mut arcs = Vec::new();
            boundary_pieces(&light, &occ, &mut scratch, |p| {
                arcs.push((map(p.start), map(p.end)))
            });
            crossing += arcs.iter().any(|(a, b)| (a.z < 0.0) != (b.z < 0.0)) as usize;
            let b = clamped_integral_of_boundary(arcs, &mut crossings, edge_integral)
                .expect("the crossings alternate")
                / TAU;
            let scale = form_factor(light.loops()).abs().max(1e-3);
            assert!(
                (b - gh).abs() <= 1e-10 * scale,
                "case {case}: boundary {b} vs Greiner–Hormann {gh}"
            );
            checked += 1;
        }
        assert!(checked > 1800 && crossing > 200, "{checked} {crossing}");
    }

    #[test]
    fn agrees_with_monte_carlo() {
        let mut rng = Pcg32::new(99, 3);
        let mut mc_rng = Pcg32::new(5, 11);
        for _ in 0..6 {
            let (light, occ) = random_config(&mut rng);
            let b = boundary_ff(&light, &occ);
            let (m, se) = mc_ff(&light, &occ, 200_000, &mut mc_rng);
            assert!((b - m).abs() < 5.0 * se, "boundary {b} MC {m} ± {se}");
        }
    }

    /// The light quad of the degenerate cases, centred on +z.
    fn light_quad() -> [DVec3; 4] {
        [
            DVec3::new(-0.5, -0.4, 1.0).normalize(),
            DVec3::new(0.5, -0.4, 1.0).normalize(),
            DVec3::new(0.5, 0.4, 1.0).normalize(),
            DVec3::new(-0.5, 0.4, 1.0).normalize(),
        ]
    }

    /// Oracle: the same occluder as one quad (GH and the boundary), for a quad split along a
    /// diagonal into two triangles whose shared edge crosses the light: the shared edge is
    /// dropped (the regions on its two sides are both occluded), not counted twice.
    #[test]
    fn shared_edge_of_two_occluder_triangles_is_dropped() {
        let light = poly(&light_quad());
        let q = [
            DVec3::new(-0.2, -0.9, 1.0).normalize(),
            DVec3::new(0.3, -0.7, 1.0).normalize(),
            DVec3::new(0.9, 0.9, 1.0).normalize(),
            DVec3::new(-0.1, 0.6, 1.0).normalize(),
        ];
        let quad = poly(&q);
        let t1 = poly(&[q[0], q[1], q[2]]);
        let t2 = poly(&[q[0], q[2], q[3]]);
        let whole = gh_ff(&light, std::slice::from_ref(&quad)).unwrap();
        let split = boundary_ff(&light, &[t1.clone(), t2.clone()]);
        assert!(rel_err(split, whole) < 1e-12, "{split} {whole}");
        assert!(rel_err(boundary_ff(&light, &[t2.clone(), t1.clone()]), whole) < 1e-12);
        assert!(rel_err(boundary_ff(&light, &[quad]), whole) < 1e-12);
        let gh_split = gh_ff(&light, &[t1.clone(), t2.clone()]).unwrap();
        assert!(rel_err(split, gh_split) < 1e-10);
        // No piece lies on the shared diagonal q0–q2.
        let mut s = BoundaryScratch::new();
        let n = q[0].cross(q[2]).normalize();
        boundary_pieces(&light, &[t1, t2], &mut s, |p| {
            let on = n.dot(p.start).abs() < 1e-12 && n.dot(p.end).abs() < 1e-12;
            assert!(!on || matches!(p.source, PieceSource::Light), "{p:?}");
        });
    }

    /// Oracle: the visible part written down directly (its form factor), for occluders that
    /// cover part of the light with edges on the light's edges: the left half (three coincident
    /// edges, the same direction as the light's: dropped), the whole light (nothing left), the
    /// light twice, and a neighbour outside sharing one edge in the opposite direction (the
    /// light's edge kept, once).
    #[test]
    fn coincident_edges_with_the_light() {
        let l = light_quad();
        let light = poly(&l);
        let m01 = (l[0] + l[1]).normalize();
        let m32 = (l[3] + l[2]).normalize();
        let left = poly(&[l[0], m01, m32, l[3]]);
        let right = poly(&[m01, l[1], l[2], m32]);
        let want = form_factor(right.loops());
        let got = boundary_ff(&light, std::slice::from_ref(&left));
        assert!(rel_err(got, want) < 1e-12, "{got} {want}");
        let gh = gh_ff(&light, std::slice::from_ref(&left)).unwrap();
        assert!(rel_err(got, gh) < 1e-10, "{got} {gh}");
        // Both halves, each edge on the light or on the other half.
        assert!(boundary_ff(&light, &[left.clone(), right.clone()]).abs() < 1e-14);
        // The light itself, once and twice.
        assert!(boundary_ff(&light, std::slice::from_ref(&light)).abs() < 1e-14);
        assert!(boundary_ff(&light, &[light.clone(), light.clone()]).abs() < 1e-14);
        // A neighbour beyond the right edge l1–l2, sharing it in the opposite direction.
        let far = |v: DVec3| DVec3::new(v.x + 0.6, v.y, v.z);
        let nb = poly(&[l[1], far(l[1]), far(l[2]), l[2]]);
        let full = form_factor(light.loops());
        let got = boundary_ff(&light, std::slice::from_ref(&nb));
        assert!(rel_err(got, full) < 1e-12, "{got} {full}");
        let mut count = 0;
        boundary_pieces(
            &light,
            std::slice::from_ref(&nb),
            &mut BoundaryScratch::new(),
            |_| count += 1,
        );
        assert_eq!(count, 4);
    }

    /// Oracle: 0 for an occluder containing the light, `form_factor(light)` for one that misses
    /// it or lies inside it as a hole (then also GH).
    #[test]
    fn covering_missing_and_inside() {
        let light = poly(&light_quad());
        let full = form_factor(light.loops());
        let big = regular(DVec3::Z, 1.5, 6, 0.1);
        assert!(boundary_ff(&light, std::slice::from_ref(&big)).abs() < 1e-15);
        let away = regular(dir(0.3, 2.0), 0.2, 5, 0.0);
        assert_eq!(boundary_ff(&light, std::slice::from_ref(&away)), {
            let mut s = BoundaryScratch::new();
            visible_integral_from_boundary(
                &light,
                [] as [&SphericalPolygon; 0],
                &mut s,
                edge_integral,
            ) / TAU
        });
        assert!(rel_err(boundary_ff(&light, &[]), full) < 1e-15);
        let small = regular(DVec3::Z, 0.1, 7, 0.3);
        let want = full - form_factor(small.loops());
        let got = boundary_ff(&light, std::slice::from_ref(&small));
        assert!(rel_err(got, want) < 1e-12);
        assert!(rel_err(got, gh_ff(&light, &[small]).unwrap()) < 1e-10);
    }

    /// Oracles: GH and Monte Carlo, for a light and occluders that reach below the horizon:
    /// after clipping both have horizon edges, the occluder's lying on the light's in the same
    /// direction (dropped), and the horizon piece of the light outside the occluder is kept
    /// (its edge integral is its azimuthal angle, not zero).
    #[test]
    fn horizon_edges_on_the_light_horizon_edge() {
        let light = clipped(&regular(dir(0.15, 0.0), 0.6, 5, 0.2));
        assert!(light.vertices().iter().any(|v| v.z == 0.0));
        let occ = vec![
            clipped(&regular(dir(0.0, 0.25), 0.3, 4, 0.4)),
            clipped(&regular(dir(0.05, -0.3), 0.25, 6, 0.0)),
        ];
        let b = boundary_ff(&light, &occ);
        let gh = gh_ff(&light, &occ).unwrap();
        assert!(rel_err(b, gh) < 1e-10, "{b} {gh}");
        let (m, se) = mc_ff(&light, &occ, 400_000, &mut Pcg32::new(1, 2));
        assert!((b - m).abs() < 5.0 * se, "{b} {m} ± {se}");
        // Both occluders have horizon arcs overlapping the light's horizon arc.
        let (lo, hi) = light
            .vertices()
            .iter()
            .filter(|v| v.z == 0.0)
            .map(|v| v.y.atan2(v.x))
            .fold((PI, -PI), |(a, b), f| (a.min(f), b.max(f)));
        for o in &occ {
            assert!(o.vertices().iter().any(|v| {
                let f = v.y.atan2(v.x);
                v.z == 0.0 && f > lo && f < hi
            }));
        }
        // Some kept piece lies on the horizon, none of an occluder.
        let mut horizon_terms = 0.0;
        boundary_pieces(&light, &occ, &mut BoundaryScratch::new(), |p| {
            if p.start.z == 0.0 && p.end.z == 0.0 {
                assert_eq!(p.source, PieceSource::Light);
                horizon_terms += edge_integral(p.start, p.end);
            }
        });
        assert!(horizon_terms.abs() > 1e-3);
    }

    /// Oracles: the occluder as one polygon (the boundary path and GH), for occluders given as
    /// the triangles of a fan (each clipped to the horizon on its own, as faces taken one by
    /// one are): edges shared by two triangles, vertices shared by all, on 500 random
    /// configurations.
    #[test]
    fn fan_triangulated_occluders_match_the_whole() {
        let mut rng = Pcg32::new(17, 4);
        let mut worst = 0.0f64;
        for case in 0..500 {
            let el = rng.range(0.05, 1.4);
            let az = rng.range(0.0, TAU);
            let mut light = SphericalPolygon::new();
            random_star_loop(&mut light, &Frame::from_z(dir(el, az)), 6, 0.7, &mut rng);
            let light = clipped(&light);
            let oc = dir(
                (el + rng.range(-0.4, 0.4)).max(-0.2),
                az + rng.range(-0.5, 0.5),
            );
            let mut star = SphericalPolygon::new();
            // Four or more points: the angle of each triangle at the centre stays below π.
            let k = 4 + (rng.next_f64() * 6.0) as usize;
            random_star_loop(&mut star, &Frame::from_z(oc), k, 0.6, &mut rng);
            let ring = star.loop_at(0).to_vec();
            let fan: Vec<SphericalPolygon> = (0..k)
                .map(|j| clipped(&poly(&[oc, ring[j], ring[(j + 1) % k]])))
                .filter(|t| !t.is_empty())
                .collect();
            let whole = [clipped(&star)];
            let Some(gh) = gh_ff(&light, &whole) else {
                continue;
            };
            let b_whole = boundary_ff(&light, &whole);
            let b_fan = boundary_ff(&light, &fan);
            for b in [b_whole, b_fan] {
                let err = rel_err(b, gh);
                assert!(err < 1e-10, "case {case}: {b_whole} {b_fan} GH {gh}");
                worst = worst.max(err);
            }
        }
        println!("fans: max rel diff {worst:e}");
    }

    /// Oracle: the other part written down (`form_factor`) and GH, for an occluder that is the
    /// light cut by a great circle through it: every occluder edge but the cut lies on a light
    /// edge in the same direction, its vertices are the light's; 500 random cuts of convex and
    /// non-convex lights.
    #[test]
    fn occluder_cut_from_the_light() {
        use crate::geometry::spherical::spherical_polygon::clip_loop_to_half_spaces;
        let mut rng = Pcg32::new(8, 8);
        let (mut tmp, mut part, mut rest) = (Vec::new(), Vec::new(), Vec::new());
        let mut worst = 0.0f64;
        for case in 0..500 {
            let c = dir(rng.range(0.3, 1.5), rng.range(0.0, TAU));
            let lp = if case % 2 == 0 {
                regular(c, rng.range(0.2, 0.8), 3 + case % 5, rng.range(0.0, TAU))
            } else {
                let mut l = SphericalPolygon::new();
                random_star_loop(&mut l, &Frame::from_z(c), 7, 0.6, &mut rng);
                l
            };
            let light = clipped(&lp);
            // A great circle through the light's centre direction.
            let n = c.cross(rng.unit_vector()).normalize();
            clip_loop_to_half_spaces(light.loop_at(0), &[n], &mut part, &mut tmp);
            clip_loop_to_half_spaces(light.loop_at(0), &[-n], &mut rest, &mut tmp);
            if part.is_empty() || rest.is_empty() {
                continue;
            }
            // The cut is of the light's first loop: skip lights the horizon left in several
            // loops. (For a non-convex light the part may run along the cut twice, in opposite
            // directions; those pieces cancel.)
            if light.loop_count() != 1 {
                continue;
            }
            let occ = [poly(&part)];
            let b = boundary_ff(&light, &occ);
            let want = form_factor([rest.as_slice()]);
            let err = rel_err(b, want);
            assert!(err < 1e-10, "case {case}: {b} want {want}");
            worst = worst.max(err);
            if let Some(gh) = gh_ff(&light, &occ) {
                assert!(rel_err(b, gh) < 1e-10, "case {case}: {b} GH {gh}");
            }
        }
        println!("cuts: max rel diff {worst:e}");
    }

    /// Timing, not a check (`cargo test --release --lib boundary_integral::tests::timing --
    /// --ignored --nocapture`): per configuration of the random test, the GH path (project,
    /// subtract per occluder, reproject, `form_factor`) against the boundary sum, both with
    /// warm scratch buffers, best of five passes.
    #[test]
    #[ignore]
    fn timing_boundary_against_greiner_hormann() {
        use std::time::Instant;
        let mut rng = Pcg32::new(2021, 7);
        let configs: Vec<_> = (0..2000).map(|_| random_config(&mut rng)).collect();
        let plane = ProjectionPlane::NORMAL;
        let (mut v, mut clip, mut out) = (
            PlanarPolygon::new(),
            PlanarPolygon::new(),
            PlanarPolygon::new(),
        );
        let mut sph = SphericalPolygon::new();
        let mut sd = SetDifference::new();
        let mut bs = BoundaryScratch::new();
        let (mut best_gh, mut best_b) = (f64::INFINITY, f64::INFINITY);
        let mut sink = 0.0;
        for _ in 0..5 {
            let t = Instant::now();
            for (light, occ) in &configs {
                plane.project(light, &mut v);
                for o in occ {
                    if v.is_empty() {
                        break;
                    }
                    plane.project(o, &mut clip);
                    sd.subtract(&v, &clip, &mut out, None);
                    std::mem::swap(&mut v, &mut out);
                }
                plane.reproject(&v, &mut sph);
                sink += form_factor(sph.loops());
            }
            best_gh = best_gh.min(t.elapsed().as_secs_f64());
            let t = Instant::now();
            for (light, occ) in &configs {
                sink += visible_integral_from_boundary(light, occ, &mut bs, edge_integral);
            }
            best_b = best_b.min(t.elapsed().as_secs_f64());
        }
        let n = configs.len() as f64;
        println!(
            "per configuration: GH {:.2} µs, boundary {:.2} µs, ratio boundary/GH {:.2} ({sink})",
            best_gh / n * 1e6,
            best_b / n * 1e6,
            best_b / best_gh
        );
    }

    /// Degenerate input gives a finite answer and no panic: zero-length edges, repeated
    /// vertices, antipodal vertices, empty polygons, loops of one or two vertices.
    #[test]
    fn degenerate_input_does_not_panic() {
        let l = light_quad();
        let mut light = SphericalPolygon::new();
        light.push_loop([l[0], l[0], l[1], l[2], l[2], l[3]]);
        let full = form_factor(poly(&l).loops());
        assert!(rel_err(boundary_ff(&light, &[]), full) < 1e-15);
        let mut odd = SphericalPolygon::new();
        odd.push_loop([DVec3::X, -DVec3::X, DVec3::Z]);
        odd.push_loop([DVec3::Y]);
        odd.push_loop([DVec3::Y, DVec3::Z]);
        let empty = SphericalPolygon::new();
        for occ in [vec![odd.clone()], vec![empty.clone(), odd.clone()], vec![]] {
            assert!(boundary_ff(&light, &occ).is_finite());
            assert!(boundary_ff(&odd, &occ).is_finite());
            assert!(boundary_ff(&empty, &occ) == 0.0);
        }
    }
}
