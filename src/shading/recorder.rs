//! What the debugger sees: a recording of the stages the renderer computed at one shading
//! point (rerun's split: this is the data; the workbench draws it).
//!
//! Every stage function takes `&mut impl Recorder`. The renderer passes [`NoRecorder`], whose
//! methods are empty and inline away, so recording is free when off; the workbench passes a
//! [`StageRecording`] and receives copies of every intermediate polygon of the *same* call.

use crate::geometry::spherical::cone::Cone;
use crate::geometry::{GreinerHormannSteps, PlanarPolygon, Plane, SphericalPolygon, TreeKind};
use crate::scene::environment_spec::EnvMethod;
use glam::DVec3;

/// The stages of 000 Alg. 1 that produce a polygon.
#[derive(Clone, Copy, Debug, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
pub enum Stage {
    /// Line 4/9: `SphPolySilhouette`, the silhouette as a spherical polygon.
    Silhouette,
    /// Line 5/10: `ClipToHorizon`.
    HorizonClipped,
    /// Line 13: the visible polygon after the set differences, reprojected to the sphere.
    Visible,
    /// Line 14: after `ApplyLTC` (specular lobe; the diffuse lobe uses the identity).
    LtcTransformed,
    /// Line 15: the transformed polygon clipped to the horizon again.
    LtcClipped,
}

/// Receives the intermediate results of one shading point. All methods default to no-ops.
pub trait Recorder {
    /// False for recorders that discard everything; lets stages skip work done only for them.
    const ENABLED: bool;

    fn begin_light(&mut self, _light: usize, _piece: Option<usize>) {}
    fn light_polygon(&mut self, _stage: Stage, _poly: &SphericalPolygon) {}
    fn occluder_polygon(
        &mut self,
        _occluder: usize,
        _piece: Option<usize>,
        _stage: Stage,
        _poly: &SphericalPolygon,
    ) {
    }
    /// The contour edges (001 Eq. 4.2) of the light (`occluder == None`) or of an occluder,
    /// seen from the shading point: each edge as its two endpoint directions in the shading
    /// frame, oriented counter-clockwise around its front-facing face. The silhouette stage
    /// chains exactly these edges (convex and flat meshes) or cuts its loops out of them.
    /// `world` holds the same edges' endpoints on the mesh, in world space (for views drawn in
    /// the scene rather than on the sphere).
    fn contour(&mut self, _occluder: Option<usize>, _edges: &[[DVec3; 2]], _world: &[[DVec3; 2]]) {}
    /// A lookup in the light's (`occluder == None`) or an occluder's BSP tree of silhouettes.
    fn tree_lookup(&mut self, _record: &TreeLookupRecord) {}
    /// How the exact silhouette of a closed non-convex light (`occluder == None`) or occluder
    /// was found at this point (001 Sect. 4.3, 5.2).
    fn exact_silhouette(&mut self, _record: &ExactSilhouetteRecord) {}
    /// What the point's tile shared for an occluder's outline inside the light's window
    /// (`geometry::silhouettes::tile_candidates`).
    fn tile_share(&mut self, _record: &TileShareRecord) {}
    fn culled_occluders(&mut self, _kept: &[usize]) {}
    /// One `SetDifference` of Alg. 1 line 12, taken by `method` (its Greiner–Hormann phases,
    /// if recorded, were written into [`Recorder::gh_steps`] by the call itself).
    fn set_difference(
        &mut self,
        _occluder: usize,
        _method: DifferenceMethod,
        _before: &PlanarPolygon,
        _clip: &PlanarPolygon,
        _after: &PlanarPolygon,
    ) {
    }
    fn lobe(
        &mut self,
        _lobe: Lobe,
        _transformed: &SphericalPolygon,
        _clipped: &SphericalPolygon,
        _integral: f64,
    ) {
    }
    /// One edge of the visible polygon as the derivative took it (`shading::derivative`).
    fn moving_edge(&mut self, _edge: &MovingEdge) {}
    /// The light piece's rate `d(diffuse + specular)/dθ` (`shading::shade_with_rate`).
    fn light_rate(&mut self, _rate: DVec3) {}
    fn end_light(&mut self, _diffuse: DVec3, _specular: DVec3) {}
    /// The sampled correction of the LTC over the light's visible polygon (radiance, per
    /// channel), for `--method analytic-exact` (`shading::ltc_correction`).
    fn correction(&mut self, _correction: DVec3) {}
    /// Storage for the Greiner–Hormann phases of the next set difference, if recorded.
    fn gh_steps(&mut self) -> Option<&mut GreinerHormannSteps> {
        None
    }
    /// One term of the exact environment integrals (`shading::environment_occlusion`): occluder
    /// `occluder`'s outline (or one of its faces) minus what came before it, in the shading
    /// frame, and ∫ L_SH cos over it.
    fn environment_term(
        &mut self,
        _side: EnvironmentSide,
        _occluder: usize,
        _poly: &SphericalPolygon,
        _integral: DVec3,
    ) {
    }
    /// `rt`'s cones at the point, in the shading frame: those of 002 Eq. 4 and the merged
    /// ones (Alg. 1, Eq. 5, and any clustering) that cull the rays.
    fn environment_cones(&mut self, _cones: &[Cone], _merged: &[Cone]) {}
    /// One ray of `rt` (direction in the shading frame) and what became of it (Alg. 2).
    fn environment_ray(&mut self, _dir: DVec3, _outcome: RayOutcome) {}
    /// The environment's numbers at one sub-pixel sample.
    fn environment_sample(&mut self, _sample: &EnvironmentSample) {}
}

/// The recorder of the renderer: records nothing, costs nothing.
#[derive(Clone, Copy, Debug, Default)]
pub struct NoRecorder;

impl Recorder for NoRecorder {
    const ENABLED: bool = false;
}

/// How an exact silhouette was found, for the debugger: read from the mesh's BSP tree or
/// computed on the fly; its apparent intersections, and (on the fly) the contour pieces the
/// ray test rejected. Directions are in the shading frame.
#[derive(Clone, Debug, Default, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct ExactSilhouetteRecord {
    pub occluder: Option<usize>,
    pub from_tree: bool,
    pub crossings: Vec<DVec3>,
    pub rejected: Vec<[DVec3; 2]>,
}

/// What the region of a point's tile shared for one occluder's outline inside a light's
/// window (`geometry::silhouettes::tile_candidates`), for the debugger: the region's ball, and the edges it
/// keeps as candidates for all its points (`None`: the point took the whole hierarchy, the
/// region's cone being too wide or the point outside its ball).
#[derive(Clone, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct TileShareRecord {
    pub occluder: usize,
    pub centre: DVec3,
    pub radius: f64,
    pub shared_edges: Option<u32>,
    /// The mesh's edges, for scale.
    pub mesh_edges: u32,
}

/// A lookup in a mesh's BSP tree of precomputed silhouettes (001 Sect. 5), for the debugger:
/// which tree shading read (`PreparedObject::silhouette_tree`), the planes tested on the way
/// to the point's leaf with the side taken, and whether that leaf answered (else the
/// silhouette was computed at the point).
#[derive(Clone, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct TreeLookupRecord {
    pub occluder: Option<usize>,
    pub kind: TreeKind,
    /// The shading point in the tree's frame (an instance shares its group's tree).
    pub tree_point: DVec3,
    pub steps: Vec<(Plane, bool)>,
    pub answered: bool,
}

/// Which BRDF lobe an integral belongs to.
#[derive(Clone, Copy, Debug, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
pub enum Lobe {
    Diffuse,
    Specular,
}

/// How a set difference was taken (`shading::analytic::subtract_planar`).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
pub enum DifferenceMethod {
    /// Decided before any clipping (`geometry::spherical::overlap`): the occluder misses the visible
    /// polygon (`after` is `before`) or covers it (`after` is empty).
    Classified,
    /// Greiner–Hormann (`geometry::spherical::set_difference`), its phases in `steps` when recorded.
    #[default]
    GreinerHormann,
    /// The convex visible polygon with the occluder's part inside it for a hole
    /// (`geometry::spherical::hole_difference`): `after` is `before` and that part, reversed.
    Hole,
    /// Greiner–Hormann's difference of a region held with a hole and the occluder the hole
    /// came from, taken when the next occluder overlaps it (`shading::analytic::settle_hole`);
    /// its phases in `steps` when recorded.
    HoleSettled,
}

/// One recorded set difference.
#[derive(Clone, Debug, Default, serde::Serialize, serde::Deserialize)]
pub struct SetDifferenceRecord {
    pub occluder: usize,
    #[serde(default)]
    pub method: DifferenceMethod,
    pub before: PlanarPolygon,
    pub clip: PlanarPolygon,
    pub after: PlanarPolygon,
    pub steps: Option<GreinerHormannSteps>,
}

/// The plane an edge of the visible polygon lies on, as the derivative found it
/// (docs/derivatives.md, "The support of an edge").
#[derive(Clone, Copy, Debug, Default, PartialEq, serde::Serialize, serde::Deserialize)]
pub enum EdgeSupport {
    /// The horizon: it does not move in the shading frame.
    #[default]
    Horizon,
    /// The plane through the point and the mesh edge `p → q` (world space) of prepared object
    /// `object`, moving with the motion or not.
    MeshEdge {
        object: u32,
        p: DVec3,
        q: DVec3,
        moving: bool,
    },
    /// No edge of the moving object: the edge stays.
    Still,
    /// Not found, though it may move (its pixel is masked).
    NotFound,
}

/// One edge `a → b` (shading frame) of a light piece's visible polygon, as the derivative took
/// it: its support, the rate `ν̇` of its circle's normal, and its shares of the rates of the
/// diffuse form factor `E(P)` and of the LTC lobe's `E(M⁻¹P)` (before the lobe's factors).
#[derive(Clone, Copy, Debug, Default, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct MovingEdge {
    pub a: DVec3,
    pub b: DVec3,
    /// An edge of the hole the region is held less (its share counts negatively).
    pub in_hole: bool,
    pub support: EdgeSupport,
    pub normal_rate: DVec3,
    pub diffuse: f64,
    pub lobe: f64,
}

/// Everything recorded for one light (or one face of a light on the per-triangle path).
#[derive(Clone, Debug, Default, serde::Serialize, serde::Deserialize)]
pub struct LightRecord {
    pub light: usize,
    pub piece: Option<usize>,
    pub polygons: Vec<(Stage, SphericalPolygon)>,
    pub occluders_kept: Vec<usize>,
    /// Contour edges of the light (`None`) and of the occluders met, as unit directions.
    #[serde(default)]
    pub contours: Vec<(Option<usize>, Vec<[DVec3; 2]>)>,
    /// The same edges' endpoints on the mesh, in world space.
    #[serde(default)]
    pub contour_points: Vec<(Option<usize>, Vec<[DVec3; 2]>)>,
    /// Lookups in the BSP trees of the light and the occluders met.
    #[serde(default)]
    pub trees: Vec<TreeLookupRecord>,
    /// How the exact silhouettes of non-convex meshes were found.
    #[serde(default)]
    pub exact: Vec<ExactSilhouetteRecord>,
    /// What the point's tile shared for the occluders' windowed outlines.
    #[serde(default)]
    pub tile_shares: Vec<TileShareRecord>,
    pub occluder_polygons: Vec<(usize, Option<usize>, Stage, SphericalPolygon)>,
    pub set_differences: Vec<SetDifferenceRecord>,
    /// Per lobe: the transformed and the clipped polygon, and the lobe's integral (for the
    /// specular lobe the fitted distribution's, `LtcEntry::mix(E(M⁻¹V), E(V))`).
    pub lobes: Vec<(Lobe, SphericalPolygon, SphericalPolygon, f64)>,
    /// Per lobe: the edge terms of its clipped polygon's form factor (000 Eq. 9), per loop,
    /// from the edge leaving vertex 0 (`ltc::form_factor_terms`, over 2π).
    #[serde(default)]
    pub lobe_edge_terms: Vec<(Lobe, Vec<Vec<f64>>)>,
    pub diffuse: DVec3,
    pub specular: DVec3,
    /// The sampled correction of the LTC (`analytic-exact`): `specular + correction` is an
    /// unbiased estimate of the GGX radiance.
    #[serde(default)]
    pub correction: DVec3,
    /// With a derivative (`shading::shade_with_rate`): the visible polygon's edges as it took
    /// them, and the piece's rate `d(diffuse + specular)/dθ`.
    #[serde(default)]
    pub moving_edges: Vec<MovingEdge>,
    #[serde(default)]
    pub rate: DVec3,
}

/// Which of 002's two kinds of object an environment term belongs to (Sect. 3.2): static
/// objects' shadows are in E_static (Eq. 6), dynamic objects' in E_occluded.
#[derive(Clone, Copy, Debug, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
pub enum EnvironmentSide {
    /// A term `S_k ∖ S_<k` of the static union (∫ over it is subtracted from the hemisphere's
    /// to give E_static).
    Static,
    /// A term `D_i ∖ (∪S ∪ D_<i)` of E_occluded.
    Dynamic,
}

/// One term of the exact environment integrals (`shading::environment_occlusion::union_integrals`): an
/// occluder's outline (or one of its faces) minus what came before it, in the shading frame,
/// and ∫ L_SH cos over it.
#[derive(Clone, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct EnvironmentTerm {
    pub side: EnvironmentSide,
    /// Index into the prepared scene's occluders (`Probe::occluder_names`).
    pub occluder: usize,
    pub polygon: SphericalPolygon,
    pub integral: DVec3,
}

/// What became of one ray of `rt` (002 Alg. 2).
#[derive(Clone, Copy, Debug, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
pub enum RayOutcome {
    /// Outside every merged cone: not traced (direction culling).
    Culled,
    /// Traced, hit nothing within its length.
    Escaped,
    /// Traced, first hit a static object (its shadow is in E_static already).
    Static,
    /// Traced, first hit a dynamic object: counts toward E_occluded.
    Dynamic,
}

/// One recorded ray of `rt`: its direction in the shading frame and what became of it.
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct EnvironmentRay {
    pub dir: DVec3,
    pub outcome: RayOutcome,
}

/// The environment's numbers at one sub-pixel sample, as `render::environment_passes` composed them.
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct EnvironmentSample {
    pub method: EnvMethod,
    /// E_unshadowed(n), 002 Eq. 7.
    pub unshadowed: DVec3,
    /// E_static (Eq. 6, or Eq. 7 when no static object reaches the hemisphere); `None` for
    /// the reference, which estimates E directly.
    pub e_static: Option<DVec3>,
    /// E_occluded (unfiltered); `None` for the reference.
    pub occluded: Option<DVec3>,
    /// E = max(E_static − E_occluded, 0) (Eq. 3), or the reference's estimate.
    pub irradiance: DVec3,
    /// The reference's standard error of E.
    pub stderr: Option<DVec3>,
    /// ρ/π of the surface.
    pub albedo_over_pi: DVec3,
    /// ρ/π · E: the sample's environment radiance (Eq. 2).
    pub radiance: DVec3,
}

/// Everything recorded of the environment light at one shading point.
#[derive(Clone, Debug, Default, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct EnvironmentRecord {
    /// The exact method's terms, in the order they were integrated.
    pub terms: Vec<EnvironmentTerm>,
    /// `rt`: the cones of 002 Eq. 4 (one per bounding sphere above the tangent plane) and
    /// the cones after merging (Alg. 1, Eq. 5) and any clustering, in the shading frame.
    pub cones: Vec<Cone>,
    pub merged_cones: Vec<Cone>,
    /// `rt`: every ray, traced or culled.
    pub rays: Vec<EnvironmentRay>,
    /// One per sub-pixel sample shaded.
    pub samples: Vec<EnvironmentSample>,
}

impl EnvironmentRecord {
    /// Σ of the recorded terms' integrals on one side.
    pub fn sum(&self, side: EnvironmentSide) -> DVec3 {
        self.terms
            .iter()
            .filter(|t| t.side == side)
            .map(|t| t.integral)
            .sum()
    }

    pub fn is_empty(&self) -> bool {
        self.terms.is_empty()
            && self.cones.is_empty()
            && self.merged_cones.is_empty()
            && self.rays.is_empty()
            && self.samples.is_empty()
    }
}

/// A full recording of one shading point: serialisable as the workbench's debug dump.
#[derive(Clone, Debug, Default, serde::Serialize, serde::Deserialize)]
pub struct StageRecording {
    pub lights: Vec<LightRecord>,
    /// The environment light's terms, cones, rays and numbers (absent in dumps written
    /// before the environment light existed).
    #[serde(default)]
    pub environment: EnvironmentRecord,
    /// Record the Greiner–Hormann phases too (larger dumps).
    pub record_gh_steps: bool,
    #[serde(skip)]
    steps: GreinerHormannSteps,
}

impl StageRecording {
    pub fn new(record_gh_steps: bool) -> Self {
        StageRecording {
            record_gh_steps,
            ..Default::default()
        }
    }

    fn current(&mut self) -> &mut LightRecord {
        if self.lights.is_empty() {
            self.lights.push(LightRecord::default());
        }
        self.lights.last_mut().expect("just ensured")
    }
}

impl Recorder for StageRecording {
    const ENABLED: bool = true;

    fn begin_light(&mut self, light: usize, piece: Option<usize>) {
        self.lights.push(LightRecord {
            light,
            piece,
            ..Default::default()
        });
    }
    fn light_polygon(&mut self, stage: Stage, poly: &SphericalPolygon) {
        self.current().polygons.push((stage, poly.clone()));
    }
    fn occluder_polygon(
        &mut self,
        occluder: usize,
        piece: Option<usize>,
        stage: Stage,
        poly: &SphericalPolygon,
    ) {
        self.current()
            .occluder_polygons
            .push((occluder, piece, stage, poly.clone()));
    }
    fn contour(&mut self, occluder: Option<usize>, edges: &[[DVec3; 2]], world: &[[DVec3; 2]]) {
        let cur = self.current();
        if !cur.contours.iter().any(|(o, _)| *o == occluder) {
            cur.contours.push((occluder, edges.to_vec()));
            cur.contour_points.push((occluder, world.to_vec()));
        }
    }
    fn tree_lookup(&mut self, record: &TreeLookupRecord) {
        let cur = self.current();
        if !cur.trees.iter().any(|t| t.occluder == record.occluder) {
            cur.trees.push(record.clone());
        }
    }
    fn exact_silhouette(&mut self, record: &ExactSilhouetteRecord) {
        self.current().exact.push(record.clone());
    }
    fn tile_share(&mut self, record: &TileShareRecord) {
        self.current().tile_shares.push(record.clone());
    }
    fn culled_occluders(&mut self, kept: &[usize]) {
        self.current().occluders_kept = kept.to_vec();
    }
    fn set_difference(
        &mut self,
        occluder: usize,
        method: DifferenceMethod,
        before: &PlanarPolygon,
        clip: &PlanarPolygon,
        after: &PlanarPolygon,
    ) {
        let steps = self
            .record_gh_steps
            .then(|| std::mem::take(&mut self.steps))
            .filter(|_| {
                matches!(
                    method,
                    DifferenceMethod::GreinerHormann | DifferenceMethod::HoleSettled
                )
            });
        self.current().set_differences.push(SetDifferenceRecord {
            occluder,
            method,
            before: before.clone(),
            clip: clip.clone(),
            after: after.clone(),
            steps,
        });
    }
    fn lobe(
        &mut self,
        lobe: Lobe,
        transformed: &SphericalPolygon,
        clipped: &SphericalPolygon,
        integral: f64,
    ) {
        // The terms of the form factor of the clipped polygon, as the stage added them
        // (each edge's integral over 2π), listed per loop from the edge leaving vertex 0.
        let mut terms: Vec<Vec<f64>> = clipped.loops().map(|_| Vec::new()).collect();
        crate::ltc::form_factor_terms(clipped.loops(), |li, _, t| {
            terms[li].push(t / std::f64::consts::TAU)
        });
        for t in &mut terms {
            // The sum starts with the closing edge (last → first): put it last.
            if !t.is_empty() {
                t.rotate_left(1);
            }
        }
        let cur = self.current();
        cur.lobes
            .push((lobe, transformed.clone(), clipped.clone(), integral));
        cur.lobe_edge_terms.push((lobe, terms));
    }
    fn moving_edge(&mut self, edge: &MovingEdge) {
        self.current().moving_edges.push(*edge);
    }
    fn light_rate(&mut self, rate: DVec3) {
        self.current().rate = rate;
    }
    fn end_light(&mut self, diffuse: DVec3, specular: DVec3) {
        let cur = self.current();
        cur.diffuse = diffuse;
        cur.specular = specular;
    }
    fn correction(&mut self, correction: DVec3) {
        self.current().correction = correction;
    }
    fn environment_term(
        &mut self,
        side: EnvironmentSide,
        occluder: usize,
        poly: &SphericalPolygon,
        integral: DVec3,
    ) {
        self.environment.terms.push(EnvironmentTerm {
            side,
            occluder,
            polygon: poly.clone(),
            integral,
        });
    }
    fn environment_cones(&mut self, cones: &[Cone], merged: &[Cone]) {
        self.environment.cones.extend_from_slice(cones);
        self.environment.merged_cones.extend_from_slice(merged);
    }
    fn environment_ray(&mut self, dir: DVec3, outcome: RayOutcome) {
        self.environment.rays.push(EnvironmentRay { dir, outcome });
    }
    fn environment_sample(&mut self, sample: &EnvironmentSample) {
        self.environment.samples.push(*sample);
    }
    fn gh_steps(&mut self) -> Option<&mut GreinerHormannSteps> {
        if self.record_gh_steps {
            self.steps = GreinerHormannSteps::default();
            Some(&mut self.steps)
        } else {
            None
        }
    }
}
