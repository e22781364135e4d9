//! `penumbra stress`: random and adversarial configurations against a ray-cast oracle.

use anyhow::{Context, Result, bail};
use penumbra::stress::Family;
use std::path::Path;

/// One case described (`--only INDEX`): its kind, point, meshes and both values.
pub(crate) fn describe_case(family: Family, seed: u64, index: u64, rays: u32) -> Result<()> {
    if family == Family::RealMeshes {
        let t = web_time::Instant::now();
        let (mesh, perturbation, light, shaded) =
            penumbra::stress::run_one_real(seed, index, rays).map_err(anyhow::Error::msg)?;
        say!(
            "case {index}: {mesh}, perturbed by {perturbation:e} of its radius, as the {}",
            if light { "light" } else { "occluder" }
        );
        match shaded {
            None => say!("its camera rays found no surface"),
            Some((point, analytic, estimate, sigma, violations, fallbacks)) => {
                say!("shading point {point:?}");
                say!(
                    "analytic {analytic}, ray cast {estimate} ± {sigma}; {violations} invariant \
                     violations; fallbacks {fallbacks:?}"
                );
            }
        }
        for f in
            penumbra::stress::real_boundary_failures(seed, index).map_err(anyhow::Error::msg)?
        {
            say!("boundary formulation against Greiner–Hormann: {f}");
        }
        say!(
            "{:.3} s (the group's preparation included)",
            t.elapsed().as_secs_f64()
        );
        return Ok(());
    }
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
    if let Some(d) = penumbra::stress::derivative_description(seed, index) {
        say!("derivative against central differences: {d}");
    }
    for f in penumbra::stress::boundary_failures(seed, index) {
        say!("boundary formulation against Greiner–Hormann: {f}");
    }
    Ok(())
}

/// `cases` cases from `seed`: the report on stdout (and in `json`); an error when any result
/// is invalid (NaN, infinite, negative, a panic, an invariant violated).
pub(crate) fn stress(
    family: Family,
    cases: u64,
    seed: u64,
    rays: u32,
    json: Option<&Path>,
) -> Result<()> {
    let last = std::sync::atomic::AtomicU64::new(0);
    let rep = penumbra::stress::run_family(family, cases, seed, rays, None, |done| {
        let step = (cases / 20).max(1);
        let prev = last.fetch_max(done / step, std::sync::atomic::Ordering::Relaxed);
        if done / step > prev {
            eprintln!("  {done}/{cases}");
        }
    })
    .map_err(anyhow::Error::msg)?;
    say!("{}", serde_json::to_string_pretty(&rep)?);
    if let Some(path) = json {
        std::fs::write(path, serde_json::to_string_pretty(&rep)?)
            .with_context(|| format!("{}", path.display()))?;
    }
    say!(
        "{} cases: {} invariant violations, {} bounds crossed ({} degenerate fallbacks), {} \
         hangs (cases over {} s); slowest case {:.3} s: {}; peak memory {}",
        rep.cases,
        rep.invariant_violations,
        rep.fallbacks.bounds_crossed,
        rep.fallbacks.degenerate,
        rep.timing.hangs,
        penumbra::stress::HANG_SECONDS,
        rep.timing.slowest_seconds,
        rep.timing.slowest_command,
        rep.timing
            .peak_mb
            .map_or("unknown".into(), |m| format!("{m:.0} MB"))
    );
    if rep.derivative_cases > 0 {
        say!(
            "derivatives: {} cases against central differences, {} at a topology change within \
             the step, {} with a kink at θ = 0 (no derivative), {} with an unsupported edge (masked), \
             {} where the value jumps within the step (largest jump {:.1e}), {} disagreeing; worst \
             agreeing {:.1e}",
            rep.derivative_cases,
            rep.derivative_topology,
            rep.derivative_kinks,
            rep.derivative_unsupported,
            rep.derivative_jumps,
            rep.derivative_largest_jump,
            rep.derivative_disagreements,
            rep.derivative_worst
        );
    }
    if rep.boundary.pieces > 0 {
        say!(
            "boundary formulation: {} light pieces against Greiner–Hormann ({} with occluders), \
             both lobes; {} settled by Greiner–Hormann in a frame about the light, {} by welding \
             near-copies of a vertex ({:.0e}), {} by points beside every piece of the boundary \
             (slivers Greiner–Hormann dropped, up to {:.1e}), {} beyond {:.0e} of the light's form factor; \
             worst {:.1e}",
            rep.boundary.pieces,
            rep.boundary.shadowed,
            rep.boundary.second_frame,
            rep.boundary.welded,
            penumbra::stress::boundary_agreement::WELD,
            rep.boundary.witnessed,
            rep.boundary.witnessed_worst,
            rep.boundary.disagreements,
            penumbra::stress::boundary_agreement::BOUND,
            rep.boundary.worst
        );
    }
    if rep.nan + rep.inf + rep.negative + rep.panics + rep.invariant_violations > 0 {
        bail!("stress found invalid results");
    }
    if rep.boundary.disagreements > 0 {
        bail!("stress found boundary integrals that disagree with Greiner–Hormann");
    }
    if rep.derivative_disagreements > 0 {
        bail!("stress found derivatives that disagree with central differences");
    }
    Ok(())
}
