//! A view of a recording as a figure, chosen by name and stage as a user asks for it (the
//! command line's `penumbra figure`, the Python module's `Recording.figure`): one choice of
//! what a view shows at a stage, whatever asks.

use super::sphere::{Layers, drawing, region_of_interest};
use super::stages::{Step, StepKind, plane_subject, probe_steps};
use super::{SphereCamera, Style};
use crate::figure::Figure;
use crate::inspect::Probe;
use crate::render::RenderContext;

/// Which figure of a recording: the view (`sphere`, `hemisphere`, `plane`, `light`, `bsp`,
/// `environment`), the stepper's stage (1 to M; every stage without one), the set difference
/// the plane shows when the stage names none, the light the light and bsp views show (the
/// stage's light without one), the style, the side in pixels, a camera in place of the
/// framing on the lights, and whether the hemisphere is magnified to what is drawn.
#[derive(Clone, Debug)]
pub struct FigureRequest {
    pub view: String,
    pub stage: Option<usize>,
    pub difference: usize,
    pub light: Option<String>,
    pub style: Style,
    pub size: u32,
    pub orbit: Option<SphereCamera>,
    pub fit: bool,
}

impl Default for FigureRequest {
    fn default() -> Self {
        FigureRequest {
            view: "sphere".into(),
            stage: None,
            difference: 0,
            light: None,
            style: Style::Print,
            size: 800,
            orbit: None,
            fit: false,
        }
    }
}

/// The stage `stage` (the stepper's 1 to M) as an index into `steps`; out of range, an error
/// that lists every stage with its label.
pub fn current_stage(steps: &[Step], stage: Option<usize>) -> crate::Result<Option<usize>> {
    match stage {
        None => Ok(None),
        Some(n) if (1..=steps.len()).contains(&n) => Ok(Some(n - 1)),
        Some(n) => {
            let list: Vec<String> = steps
                .iter()
                .enumerate()
                .map(|(i, s)| format!("  {:>3}  {}", i + 1, s.label))
                .collect();
            Err(crate::Error::from(format!(
                "stage {n}: the recording at this point has {} stages, numbered as the \
                 workbench's stepper numbers them:\n{}",
                steps.len(),
                list.join("\n")
            )))
        }
    }
}

/// The figure `request` asks of `probe`'s recording. The light and bsp views draw on the
/// light's mesh and tree, which come from `scene`: the context the recording was made in
/// (or one prepared the same way); the other views need only the recording.
pub fn recording_figure(
    probe: &Probe,
    scene: Option<&RenderContext>,
    request: &FigureRequest,
) -> crate::Result<Figure> {
    let steps = probe_steps(probe);
    let current = current_stage(&steps, request.stage)?;
    let step = current.map(|i| &steps[i]);
    let (size, style) = (request.size, request.style);
    match request.view.as_str() {
        "light" | "bsp" => {
            let scene = scene.ok_or_else(|| {
                format!(
                    "view {}: the light's mesh comes from the scene, which this recording \
                     does not carry",
                    request.view
                )
            })?;
            light_structure_figure(probe, scene, &steps, current, request)
        }
        "sphere" | "hemisphere" | "environment" => {
            let layers = if request.view == "environment" {
                if probe.environment.is_none() {
                    return Err(
                        "view environment: the scene has no environment light (give --env)".into(),
                    );
                }
                Layers::environment_only()
            } else {
                Layers::default()
            };
            let d = drawing(probe, step, &layers);
            Ok(if request.view == "hemisphere" {
                super::hemisphere_figure(&d, request.fit, size, style)
            } else {
                let camera = request
                    .orbit
                    .unwrap_or_else(|| SphereCamera::framed(&region_of_interest(probe, step)));
                super::sphere_figure(&d, &camera, size, style)
            })
        }
        "plane" => {
            let at_difference =
                current.is_some_and(|i| matches!(steps[i].kind, StepKind::SetDifference { .. }));
            let (sd, phase) = if at_difference {
                match plane_subject(probe, &steps, current) {
                    Some((sd, phase)) => (Some(sd), phase),
                    None => (None, None),
                }
            } else {
                let all: Vec<_> = probe
                    .recording
                    .lights
                    .iter()
                    .flat_map(|l| &l.set_differences)
                    .collect();
                (all.get(request.difference).copied(), None)
            };
            let Some(sd) = sd else {
                let n: usize = probe
                    .recording
                    .lights
                    .iter()
                    .map(|l| l.set_differences.len())
                    .sum();
                return Err(crate::Error::from(format!(
                    "view plane: no set difference {} at this point (the recording has {n}; \
                     pick a pixel in a penumbra)",
                    request.difference
                )));
            };
            let name = probe
                .occluder_names
                .get(sd.occluder)
                .cloned()
                .unwrap_or_else(|| format!("#{}", sd.occluder));
            Ok(super::plane_figure(sd, &name, phase, size, style))
        }
        other => Err(crate::Error::from(format!(
            "view {other}: expected sphere, hemisphere, plane, light, bsp or environment"
        ))),
    }
}

/// The light structure (`light`) or its BSP tree's planes (`bsp`) of the light `request`
/// names, or else of the current stage's light (the first light recorded at every stage).
/// The mesh and tree come from `scene`; what is drawn on them comes from the recording.
fn light_structure_figure(
    probe: &Probe,
    scene: &RenderContext,
    steps: &[Step],
    current: Option<usize>,
    request: &FigureRequest,
) -> crate::Result<Figure> {
    use super::light::{LightCamera, light_figure};
    let light = match &request.light {
        Some(name) => probe
            .lights
            .iter()
            .find(|l| &l.name == name)
            .map(|l| l.light)
            .ok_or_else(|| {
                let names: Vec<&str> = probe.lights.iter().map(|l| l.name.as_str()).collect();
                format!("light {name}: the lights are {}", names.join(", "))
            })?,
        None => {
            let record = current.map_or(0, |i| steps[i].record);
            probe
                .recording
                .lights
                .get(record)
                .map(|r| r.light)
                .ok_or("the recording at this point has no light")?
        }
    };
    let &(id, _) = scene
        .prepared
        .lights
        .get(light)
        .ok_or_else(|| format!("scene '{}' has no light {light}", probe.scene))?;
    let obj = &scene.prepared.objects[id as usize];
    let record = probe
        .recording
        .lights
        .iter()
        .find(|r| r.light == light && r.piece.is_none());
    let mut camera = LightCamera::default();
    if let Some(o) = request.orbit {
        (camera.yaw, camera.pitch, camera.zoom) = (o.yaw, o.pitch, o.zoom);
    }
    if request.view == "bsp" {
        camera.levels = 2;
    } else {
        camera.path_planes = false;
    }
    let point = probe.point.map(|p| p.position);
    Ok(light_figure(obj, point, record, &camera, request.size, request.style).0)
}
