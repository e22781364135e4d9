//! The numbers pane: the picked point's numbers (radiance, per light and lobe, the environment
//! terms) and the Monte Carlo check of them.

use super::super::*;
use super::PaneView;
use crate::inspect::Probe;
use crate::shading::{EnvironmentSide, RayOutcome};

/// Draws the picked point's recorded numbers; no state of its own.
#[derive(Default)]
pub struct NumbersPane;

impl PaneView for NumbersPane {
    fn ui(&mut self, ui: &mut Ui, app: &mut AppState) {
        let Some(ins) = &app.inspector else {
            ui.label("Click a pixel to inspect its shading point, or open a debug dump.");
            return;
        };
        point_numbers_ui(ui, &ins.probe, app.monte_carlo.as_ref());
        derivative_ui(ui, &ins.probe);
        environment_ui(ui, &ins.probe);
        if ui.button("Monte Carlo check (65536 samples)").clicked() {
            app.run_command(Command::MonteCarloCheck);
        }
    }
}

/// The numbers of the point: per light U and S, solid angles, the MC check.
fn point_numbers_ui(ui: &mut Ui, p: &Probe, monte_carlo: Option<&MonteCarloEstimate>) {
    let Some(sp) = p.point else {
        ui.label("The ray hits nothing.");
        return;
    };
    egui::Grid::new("point_numbers")
        .num_columns(2)
        .striped(true)
        .show(ui, |ui| {
            ui.label("pixel");
            ui.label(format!(
                "({:.1}, {:.1}) of {}×{}",
                p.pixel.0, p.pixel.1, p.size.0, p.size.1
            ));
            ui.end_row();
            ui.label("object");
            ui.label(p.object_name.clone().unwrap_or_default());
            ui.end_row();
            ui.label("position");
            ui.label(fmt3(sp.position));
            ui.end_row();
            ui.label("normal");
            ui.label(fmt3(sp.normal));
            ui.end_row();
            ui.label("view");
            ui.label(fmt3(sp.view));
            ui.end_row();
            if let Some(m) = &p.material {
                ui.label("material");
                ui.label(format!(
                    "{}: kd {} ks {} α {:.3}",
                    m.name,
                    fmt3(m.kd),
                    fmt3(m.ks),
                    m.alpha
                ));
                ui.end_row();
            }
            ui.label("radiance");
            ui.label(RichText::new(fmt3(p.radiance)).strong());
            ui.end_row();
            if let Some(c) = &p.correction {
                // analytic-exact: radiance = LTC + this sampled correction.
                ui.label("GGX − LTC (sampled)");
                ui.label(format!(
                    "{} ± {} (95 %, {} directions per light)",
                    fmt3(c.value),
                    fmt3(c.stderr * 1.96),
                    c.samples
                ));
                ui.end_row();
            }
            if let Some(mc) = monte_carlo {
                ui.label("Monte Carlo");
                ui.label(format!(
                    "{} ± {} (95 %, {} samples)",
                    fmt3(mc.mean + p.emitted),
                    fmt3(mc.stderr * 1.96),
                    mc.samples
                ));
                ui.end_row();
            }
        });
    ui.add_space(4.0);
    let corrected = p.correction.is_some();
    egui::Grid::new("light_numbers")
        .num_columns(5 + usize::from(corrected))
        .striped(true)
        .show(ui, |ui| {
            ui.strong("light");
            ui.strong("unshadowed U");
            ui.strong("shadowed S");
            if corrected {
                ui.strong("GGX − LTC");
            }
            ui.strong("solid angle (sr)");
            ui.strong("visible");
            ui.end_row();
            for l in &p.lights {
                ui.label(&l.name);
                ui.label(fmt3(l.unshadowed));
                ui.label(fmt3(l.shadowed));
                if corrected {
                    ui.label(fmt3(l.correction));
                }
                ui.label(format!("{:.5}", l.solid_angle));
                ui.label(format!("{:.1} %", 100.0 * l.visible_fraction()));
                ui.end_row();
            }
        });
}

/// The derivative at the point (`Probe::derivative`): the point's rate, and per light record
/// its rate and each moving edge (`views::stages::moves`) with its support, its outward
/// normal speed at the midpoint and its shares of the rates of the diffuse form factor and of
/// the LTC lobe; the still edges are counted.
fn derivative_ui(ui: &mut Ui, p: &Probe) {
    use crate::shading::EdgeSupport;
    let Some(d) = &p.derivative else {
        return;
    };
    ui.add_space(4.0);
    ui.strong(format!("derivative {}", d.label()));
    let mut notes = Vec::new();
    if d.unsupported > 0 {
        notes.push(format!("{} edges without support (masked)", d.unsupported));
    }
    if d.near_table_node {
        notes.push("near an LTC table node (masked)".into());
    }
    if d.degenerate {
        notes.push("degenerate rates (masked)".into());
    }
    ui.label(format!(
        "rate d radiance/dθ = {}{}",
        fmt3(d.rate),
        if notes.is_empty() {
            String::new()
        } else {
            format!("; {}", notes.join(", "))
        }
    ));
    let light_name = |l: usize| {
        p.lights
            .iter()
            .find(|s| s.light == l)
            .map_or_else(|| l.to_string(), |s| s.name.clone())
    };
    if p.recording.lights.iter().all(|l| l.moving_edges.is_empty()) {
        ui.label(format!(
            "Nothing seen from this point moves with {}: no edge has a rate.",
            d.object_name
        ));
    }
    for (r, rec) in p.recording.lights.iter().enumerate() {
        if rec.moving_edges.is_empty() {
            continue;
        }
        let who = match rec.piece {
            Some(f) => format!("{} face {f}", light_name(rec.light)),
            None => light_name(rec.light),
        };
        let moving: Vec<_> = rec
            .moving_edges
            .iter()
            .filter(|e| crate::views::stages::moves(e))
            .collect();
        ui.label(format!(
            "light {who}: rate {}; {} of {} edges move",
            fmt3(rec.rate),
            moving.len(),
            rec.moving_edges.len()
        ));
        if moving.is_empty() {
            continue;
        }
        egui::Grid::new(("moving_edges", r))
            .num_columns(5)
            .striped(true)
            .show(ui, |ui| {
                ui.strong("edge");
                ui.strong("support");
                ui.strong("v_n at midpoint");
                ui.strong("diffuse share");
                ui.strong("lobe share");
                ui.end_row();
                for (k, e) in moving.iter().enumerate() {
                    ui.label(format!("{k}{}", if e.in_hole { " (hole)" } else { "" }));
                    ui.label(match e.support {
                        EdgeSupport::Horizon => "horizon",
                        EdgeSupport::MeshEdge { moving: true, .. } => "edge of the moving mesh",
                        EdgeSupport::MeshEdge { .. } => "edge of a still mesh",
                        EdgeSupport::Still => "still",
                        EdgeSupport::NotFound => "not found",
                    });
                    let m = (e.a.normalize_or_zero() + e.b.normalize_or_zero()).normalize_or_zero();
                    ui.label(format!("{:+.4e}", m.dot(e.normal_rate)));
                    ui.label(format!("{:+.4e}", e.diffuse));
                    ui.label(format!("{:+.4e}", e.lobe));
                    ui.end_row();
                }
            });
    }
}

/// The environment's numbers at the point (paper 002): E_unshadowed (Eq. 7), E_static,
/// E_occluded, E (Eq. 3) and ρ/π·E, the exact integrals beside a ray-traced method's,
/// and the union terms with their integrals and sums.
fn environment_ui(ui: &mut Ui, p: &Probe) {
    let Some(e) = &p.environment else {
        return;
    };
    let rec = &p.recording.environment;
    ui.add_space(4.0);
    let method = e.settings.map_or("?", |s| s.method.name());
    ui.strong(format!(
        "environment {} (rotate {:.0}°, scale {}), {method}",
        e.label, e.rotate_deg, e.scale
    ));
    egui::Grid::new("environment_numbers")
        .num_columns(2)
        .striped(true)
        .show(ui, |ui| {
            let mut row = |name: &str, value: String| {
                ui.label(name);
                ui.label(value);
                ui.end_row();
            };
            if let Some(s) = &e.sample {
                row("E_unshadowed (Eq. 7)", fmt3(s.unshadowed));
                if let Some(st) = s.e_static {
                    row("E_static", fmt3(st));
                }
                if let Some(oc) = s.occluded {
                    row("E_occluded", fmt3(oc));
                }
                row("E (Eq. 3)", fmt3(s.irradiance));
                if let Some(se) = s.stderr {
                    row("standard error of E", fmt3(se));
                }
                row("ρ/π · E", fmt3(s.radiance));
            }
            if e.filtered_in_render {
                row(
                    "",
                    "(the render filters E_occluded 5×5: its pixel differs)".into(),
                );
            }
            if method != "analytic" {
                if let Some(st) = e.exact_static {
                    row("exact E_static", fmt3(st));
                }
                if let Some(oc) = e.exact_occluded {
                    row("exact E_occluded", fmt3(oc));
                }
            }
            if !rec.rays.is_empty() {
                let count = |o: RayOutcome| rec.rays.iter().filter(|r| r.outcome == o).count();
                row(
                    "rays",
                    format!(
                        "{} traced ({} hit dynamic, {} static, {} escaped), {} culled of {}",
                        rec.rays.len() - count(RayOutcome::Culled),
                        count(RayOutcome::Dynamic),
                        count(RayOutcome::Static),
                        count(RayOutcome::Escaped),
                        count(RayOutcome::Culled),
                        rec.rays.len()
                    ),
                );
                row(
                    "cones",
                    format!(
                        "{} (Eq. 4), {} merged (Alg. 1)",
                        rec.cones.len(),
                        rec.merged_cones.len()
                    ),
                );
            }
        });
    let terms = if rec.terms.is_empty() {
        &e.exact_terms
    } else {
        &rec.terms
    };
    if terms.is_empty() {
        return;
    }
    ui.label(if rec.terms.is_empty() {
        "union terms of the exact method (for comparison):"
    } else {
        "union terms integrated:"
    });
    let name = |i: usize| {
        p.occluder_names
            .get(i)
            .cloned()
            .unwrap_or_else(|| format!("#{i}"))
    };
    egui::Grid::new("environment_terms")
        .num_columns(4)
        .striped(true)
        .show(ui, |ui| {
            ui.strong("term");
            ui.strong("occluder");
            ui.strong("vertices");
            ui.strong("∫ L cos (RGB)");
            ui.end_row();
            for t in terms {
                ui.label(match t.side {
                    EnvironmentSide::Static => "S_k − S_<k",
                    EnvironmentSide::Dynamic => "D_i − S − D_<i",
                });
                ui.label(name(t.occluder));
                ui.label(t.polygon.vertices().len().to_string());
                ui.label(fmt3(t.integral));
                ui.end_row();
            }
            let sums = [
                (EnvironmentSide::Static, "Σ static"),
                (EnvironmentSide::Dynamic, "Σ dynamic = E_occluded"),
            ];
            for (side, label) in sums {
                let sum: glam::DVec3 = terms
                    .iter()
                    .filter(|t| t.side == side)
                    .map(|t| t.integral)
                    .sum();
                ui.strong(label);
                ui.label("");
                ui.label("");
                ui.strong(fmt3(sum));
                ui.end_row();
            }
        });
}

fn fmt3(v: glam::DVec3) -> String {
    format!("({:.5}, {:.5}, {:.5})", v.x, v.y, v.z)
}
