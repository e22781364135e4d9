//! Export ▸ Figure: the figure a pane shows, written as SVG, PDF or PNG (`figure::save`) from
//! the same description the pane paints, at a print size and, by default, in the print style.
//! `penumbra figure` writes the same figures from the command line.

use super::WorkbenchApp;
use super::ui::{PlanarPane, SphereFigure};
use crate::figure::Figure;
use crate::views::Style;
use crate::views::sphere::{Layers, drawing};
use std::path::Path;

/// A pane whose picture is a figure.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum FigureView {
    Sphere,
    Hemisphere,
    Plane,
    LightStructure,
    Environment,
    BenchChart,
}

impl FigureView {
    pub const ALL: [FigureView; 6] = [
        FigureView::Sphere,
        FigureView::Hemisphere,
        FigureView::Plane,
        FigureView::LightStructure,
        FigureView::Environment,
        FigureView::BenchChart,
    ];

    /// The menu's words, and `penumbra figure --view`'s name for the same figure.
    pub(crate) fn title(self) -> &'static str {
        match self {
            FigureView::Sphere => "the unit sphere",
            FigureView::Hemisphere => "the hemisphere",
            FigureView::Plane => "the projected plane",
            FigureView::LightStructure => "the light structure",
            FigureView::Environment => "the environment on the sphere",
            FigureView::BenchChart => "the bench chart",
        }
    }

    /// The file name offered.
    pub fn file_stem(self) -> &'static str {
        match self {
            FigureView::Sphere => "sphere",
            FigureView::Hemisphere => "hemisphere",
            FigureView::Plane => "plane",
            FigureView::LightStructure => "light",
            FigureView::Environment => "environment",
            FigureView::BenchChart => "time_vs_rmse",
        }
    }
}

/// Side of an exported figure in pixels (SVG user units, PDF points).
pub(crate) const EXPORT_SIDE: u32 = 800;

impl WorkbenchApp {
    /// The figure `view` shows now, `side` pixels square (the chart `side` wide), or why there
    /// is none (nothing picked, no set difference at the point, no light selected...).
    pub(crate) fn view_figure(
        &self,
        view: FigureView,
        side: u32,
        style: Style,
    ) -> crate::Result<Figure> {
        let pick_first = || "pick a point first".to_string();
        let ins = self.inspector.as_ref();
        match view {
            FigureView::Sphere | FigureView::Hemisphere => {
                let ins = ins.ok_or_else(pick_first)?;
                let which = if view == FigureView::Sphere {
                    SphereFigure::Sphere
                } else {
                    SphereFigure::Hemisphere
                };
                Ok(self
                    .settings
                    .sphere
                    .figure(which, &ins.probe, ins.current(), side, style))
            }
            FigureView::Environment => {
                let ins = ins.ok_or_else(pick_first)?;
                if ins.probe.environment.is_none() {
                    return Err("the scene has no environment light".into());
                }
                let d = drawing(&ins.probe, ins.current(), &Layers::environment_only());
                let camera = self.settings.sphere.camera_for(&ins.probe, ins.current());
                Ok(crate::views::sphere_figure(&d, &camera, side, style))
            }
            FigureView::Plane => PlanarPane::figure(ins.ok_or_else(pick_first)?, side, style)
                .ok_or_else(|| "no occluder is subtracted at this point".into()),
            FigureView::LightStructure => {
                let (obj, point, record) = self
                    .panes
                    .light_structure
                    .subject(&self.app)
                    .ok_or("select a light in the light structure pane")?;
                Ok(self
                    .panes
                    .light_structure
                    .view
                    .figure(obj, point, record, side, style)
                    .0)
            }
            FigureView::BenchChart => {
                let report = self.bench.as_ref().ok_or("run or open a bench first")?;
                let chart = crate::bench::output::time_vs_rmse_chart(report);
                Ok(crate::figure::plot::chart_figure(
                    &chart,
                    side,
                    side * 5 / 8,
                ))
            }
        }
    }

    /// Writes the figure of `view` to `path` (.svg, .pdf or .png) in the export style.
    pub fn export_figure(&mut self, view: FigureView, path: &Path) -> crate::Result<()> {
        let style = if self.figure_print {
            Style::Print
        } else {
            Style::Screen
        };
        let fig = self.view_figure(view, EXPORT_SIDE, style)?;
        crate::figure::save(&fig, path).map_err(|e| format!("{e:#}"))?;
        self.status = format!("wrote {} ({})", path.display(), view.title());
        Ok(())
    }

    /// Asks where to write the figure of `view`, then writes it (downloads it in the
    /// browser).
    pub(in crate::app) fn export_figure_dialog(&mut self, view: FigureView) {
        let name = format!("{}.svg", view.file_stem());
        let Some(target) = super::platform::save_as("figure", &["svg", "pdf", "png"], &name) else {
            return;
        };
        let style = if self.figure_print {
            Style::Print
        } else {
            Style::Screen
        };
        let figure = match self.view_figure(view, EXPORT_SIDE, style) {
            Ok(f) => f,
            Err(e) => {
                self.status = format!("figure not written: {e}");
                return;
            }
        };
        let format = target.extension();
        self.status = target.write(
            |p| crate::figure::save(&figure, p),
            || crate::figure::to_bytes(&figure, &format),
        );
    }
}
