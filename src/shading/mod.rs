//! Shading one point: 000 Alg. 1 for every light, with the scene prepared once.

pub(crate) mod analytic;
pub mod brdf;
pub mod cost_model;
pub mod derivative;
pub(crate) mod environment_occlusion;
pub mod face_sides;
pub mod get_between;
pub(crate) mod invariant;
pub(crate) mod ltc_correction;
pub(crate) mod outline;
pub(crate) mod prepared;
pub(crate) mod recorder;
pub mod tree_cache;
pub(crate) mod tree_library;

pub use analytic::{
    CorrectedRadiance, RateNotes, ShadingScratch, ShadingStats, Shortcuts, analytic_exact_pixel,
    shade, shade_corrected, shade_with_rate,
};
pub use environment_occlusion::{
    EnvironmentIntegrals, EnvironmentOccluders, EnvironmentPass, EnvironmentRates,
    environment_integrals, environment_integrals_with_rates, shadowed_irradiance,
};
pub use invariant::visible_within_light;
pub use ltc_correction::CorrectionSampling;
pub use outline::{Fallbacks, Outline, OutlineScratch, Role};
pub use prepared::{
    BuiltTree, FanMesh, MeshPath, MeshTrees, MoveReuse, NoExactTree, PathKind, PathTree,
    PrepareConfig, PrepareNote, PrepareOptions, PrepareReport, PreparedObject, PreparedScene,
    StandIn, instance_map,
};
pub use recorder::{
    DifferenceMethod, EdgeSupport, EnvironmentRay, EnvironmentRecord, EnvironmentSample,
    EnvironmentSide, EnvironmentTerm, ExactSilhouetteRecord, LightRecord, Lobe, MovingEdge,
    NoRecorder, RayOutcome, Recorder, SetDifferenceRecord, Stage, StageRecording, TileShareRecord,
    TreeLookupRecord,
};
pub use tree_library::{LibraryEntry, TreeLibrary};

use glam::DVec3;

crate::choice! {
    /// How visibility is computed.
    #[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, serde::Serialize, serde::Deserialize)]
    #[serde(rename_all = "kebab-case")]
    pub enum Method {
        /// 000 Alg. 1 with silhouettes of convex and flat meshes, per face for the others.
        Analytic = "analytic",
        /// 000 Sect. 4.4: every light and occluder face on its own (a baseline).
        PerTriangle = "per-triangle",
        /// LTC shading without occluders (a baseline; 003's U).
        Unshadowed = "unshadowed",
    }
}

/// A point to shade, in world space.
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct ShadingPoint {
    pub position: DVec3,
    /// Unit geometric normal, already turned toward the viewer (two-sided shading).
    pub normal: DVec3,
    /// Unit direction toward the viewer.
    pub view: DVec3,
    /// The scene object and face the point lies on, if any: excluded from its own shadowing
    /// where it cannot shadow itself.
    pub object: Option<u32>,
    pub face: Option<u32>,
}
