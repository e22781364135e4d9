//! `penumbra stress`: random and adversarial configurations against a ray-cast oracle.

use anyhow::{Context, Result, bail};
use std::path::Path;

/// One case described (`--only INDEX`): its kind, point, meshes and both values.
pub(crate) fn describe_case(seed: u64, index: u64, rays: u32) -> Result<()> {
    let (case, analytic, estimate, sigma, violations) =
        penumbra::stress::run_one(seed, index, rays);
    say!("case {index}: {:?}, scale {:e}", case.kind, case.scale);
    say!("shading point {:?}", case.point);
    for o in &case.scene.objects {
        say!(
            "{} ({} vertices): {:?}",
            o.name,
            o.mesh.positions.len(),
            o.mesh.positions
        );
    }
    say!(
        "analytic {analytic}, ray cast {estimate} ± {sigma}; {violations} invariant \
         violations"
    );
    Ok(())
}

/// `cases` cases from `seed`: the report on stdout (and in `json`); an error when any result
/// is invalid (NaN, infinite, negative, a panic, an invariant violated).
pub(crate) fn stress(cases: u64, seed: u64, rays: u32, json: Option<&Path>) -> Result<()> {
    let last = std::sync::atomic::AtomicU64::new(0);
    let rep = penumbra::stress::run(cases, seed, rays, None, |done| {
        let step = (cases / 20).max(1);
        let prev = last.fetch_max(done / step, std::sync::atomic::Ordering::Relaxed);
        if done / step > prev {
            eprintln!("  {done}/{cases}");
        }
    });
    say!("{}", serde_json::to_string_pretty(&rep)?);
    if let Some(path) = json {
        std::fs::write(path, serde_json::to_string_pretty(&rep)?)
            .with_context(|| format!("{}", path.display()))?;
    }
    if rep.nan + rep.inf + rep.negative + rep.panics + rep.invariant_violations > 0 {
        bail!("stress found invalid results");
    }
    Ok(())
}
