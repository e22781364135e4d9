//! Moving objects in the workbench: the selection, the gizmo's drag in the viewport, undo and
//! redo. The edits themselves are `scene::edit::EditHistory`'s; the re-preparation after a
//! move is `RenderContext::with_moved_object` (the moved object's trees are reused under its
//! transform, every other object's prepared data is shared). This file only turns pointer
//! input into edits and edits into new render contexts.

use super::gizmo::{Gizmo, Handle, Motion};
use crate::render::RenderContext;
use crate::scene::Camera;
use crate::scene::edit::{EditHistory, Rigid};
use crate::shading::derivative::Axis;
use egui::{Painter, Pos2, Rect, Response, Ui};
use glam::DVec3;
use std::sync::Arc;
use web_time::Instant;

/// A drag of a handle in progress.
struct HandleDrag {
    handle: Handle,
    /// The gizmo as it was when the drag began: the motion is measured from `from` on it, so
    /// the object's position depends only on where the pointer is, not on the frames between.
    gizmo: Gizmo,
    from: Pos2,
    object: usize,
    /// The context when the drag began: every frame of the drag re-prepares from it.
    base: Arc<RenderContext>,
    /// The motion so far.
    delta: Rigid,
}

/// Latency of the last update of a drag (what `penumbra gui --measure-drag` reports).
#[derive(Clone, Copy, Debug, Default, serde::Serialize)]
pub struct EditTiming {
    /// `with_moved_object`: the scene prepared again after the move (ms).
    pub prepare_ms: f64,
}

/// The selection and the edit history of the scene shown.
#[derive(Default)]
pub struct SceneEditor {
    pub selected: Option<usize>,
    history: Option<EditHistory>,
    drag: Option<HandleDrag>,
    hovered: Option<Handle>,
    pub last_timing: Option<EditTiming>,
    /// A drag driven by a program (`--measure-drag`): the context it began with.
    scripted: Option<Arc<RenderContext>>,
    /// The gizmo's active axis: the handle dragged last (or the one chosen in the scene
    /// pane), along which the derivative AOV differentiates. `None`: tx.
    axis: Option<Axis>,
}

/// What a frame of input did to the scene.
pub(crate) struct EditOutcome {
    /// The pointer is on a handle or dragging one: the viewport must not orbit.
    pub consumed: bool,
    /// The scene moved: the new context to render and probe.
    pub moved: Option<Arc<RenderContext>>,
}

impl SceneEditor {
    /// Forgets the selection and the history (a new scene was loaded).
    pub(crate) fn reset(&mut self) {
        *self = SceneEditor::default();
    }

    /// The gizmo's active axis (the handle dragged last, or chosen): the derivative AOV's.
    pub fn axis(&self) -> Axis {
        self.axis.unwrap_or(Axis::Tx)
    }

    /// Makes `axis` the active one.
    pub fn set_axis(&mut self, axis: Axis) {
        self.axis = Some(axis);
    }

    fn history(&mut self, ctx: &RenderContext) -> &mut EditHistory {
        self.history
            .get_or_insert_with(|| EditHistory::new(&ctx.scene))
    }

    pub(crate) fn can_undo(&self) -> bool {
        self.history.as_ref().is_some_and(|h| h.can_undo())
    }

    pub(crate) fn can_redo(&self) -> bool {
        self.history.as_ref().is_some_and(|h| h.can_redo())
    }

    /// The object at image position (x, y), as the renderer's primary ray hits it.
    pub(crate) fn object_at(
        ctx: &RenderContext,
        camera: &Camera,
        size: (u32, u32),
        x: f64,
        y: f64,
    ) -> Option<usize> {
        let basis = camera.basis().ok()?;
        let ray = crate::accel::Ray {
            origin: basis.eye,
            dir: basis.direction(x + 0.5, y + 0.5, size.0, size.1),
        };
        ctx.primary_hit(&ray)?.point.object.map(|o| o as usize)
    }

    /// The selected object's gizmo as drawn in the viewport `rect`.
    pub(crate) fn gizmo(
        &mut self,
        ctx: &RenderContext,
        camera: &Camera,
        rect: Rect,
    ) -> Option<Gizmo> {
        let object = self.selected?;
        let pivot = self.history(ctx).pivot(object).ok()?;
        // During a drag the gizmo follows the object.
        let pivot = match &self.drag {
            Some(d) => d.delta.apply(d.gizmo.pivot),
            None => pivot,
        };
        Some(Gizmo::new(camera.basis().ok()?, rect, pivot))
    }

    /// The viewport's input for the selected object's handles, and their drawing. Returns
    /// whether the pointer belongs to the gizmo this frame and the new context if the object
    /// moved.
    pub(crate) fn viewport_input(
        &mut self,
        ui: &Ui,
        resp: &Response,
        painter: &Painter,
        ctx: &Arc<RenderContext>,
        camera: &Camera,
    ) -> EditOutcome {
        let mut out = EditOutcome {
            consumed: false,
            moved: None,
        };
        let rect = resp.rect;
        let Some(gizmo) = self.gizmo(ctx, camera, rect) else {
            return out;
        };
        let pointer = ui.input(|i| i.pointer.interact_pos());
        if self.drag.is_none() {
            self.hovered = resp.hover_pos().and_then(|p| gizmo.hit(p));
        }
        if resp.drag_started_by(egui::PointerButton::Primary)
            && let Some(origin) = ui.input(|i| i.pointer.press_origin())
            && let Some(handle) = gizmo.hit(origin)
            && let Some(object) = self.selected
            && self.history(ctx).begin_drag(object).is_ok()
        {
            self.axis = Some(match handle {
                Handle::Axis(0) => Axis::Tx,
                Handle::Axis(1) => Axis::Ty,
                Handle::Axis(_) => Axis::Tz,
                Handle::RotateY => Axis::Ry,
            });
            self.drag = Some(HandleDrag {
                handle,
                gizmo,
                from: origin,
                object,
                base: ctx.clone(),
                delta: Rigid::IDENTITY,
            });
        }
        if let Some(d) = &self.drag {
            out.consumed = true;
            if let Some(to) = pointer
                && resp.dragged()
            {
                let delta = match d.gizmo.motion(d.handle, d.from, to) {
                    Some(Motion::Translate(t)) => Some(Rigid::translation(t)),
                    Some(Motion::RotateY(a)) => {
                        Rigid::rotation_about(d.gizmo.pivot, DVec3::Y, a).ok()
                    }
                    None => None,
                };
                let (object, base) = (d.object, d.base.clone());
                if let Some(delta) = delta {
                    out.moved = self.update(object, &base, delta);
                    if let Some(d) = &mut self.drag {
                        d.delta = delta;
                    }
                }
            }
            if resp.drag_stopped() || !ui.input(|i| i.pointer.primary_down()) {
                if let Some(h) = &mut self.history {
                    h.end_drag();
                }
                self.drag = None;
            }
        } else if self.hovered.is_some() {
            out.consumed = true;
        }
        let active = self.drag.as_ref().map(|d| d.handle);
        if let Some(g) = self.gizmo(ctx, camera, rect) {
            g.paint(painter, self.hovered, active);
        }
        out
    }

    /// Moves the dragged object to `delta` after its start and prepares the scene again from
    /// the drag's base context.
    fn update(
        &mut self,
        object: usize,
        base: &Arc<RenderContext>,
        delta: Rigid,
    ) -> Option<Arc<RenderContext>> {
        let t = Instant::now();
        let h = self.history.as_mut()?;
        h.update_drag(delta).ok()?;
        let scene = h.moved_scene(&base.scene, object).ok()?;
        let moved = base.with_moved_object(object, Arc::new(scene)).ok()?;
        self.last_timing = Some(EditTiming {
            prepare_ms: t.elapsed().as_secs_f64() * 1e3,
        });
        Some(Arc::new(moved))
    }

    /// Undoes the last move; the new context if something moved.
    pub(crate) fn undo(&mut self, ctx: &Arc<RenderContext>) -> Option<Arc<RenderContext>> {
        self.history_step(ctx, EditHistory::undo)
    }

    /// Redoes the last undone move; the new context if something moved.
    pub(crate) fn redo(&mut self, ctx: &Arc<RenderContext>) -> Option<Arc<RenderContext>> {
        self.history_step(ctx, EditHistory::redo)
    }

    /// Undo or redo: `step` writes the moved object's position into a copy of the scene.
    fn history_step(
        &mut self,
        ctx: &Arc<RenderContext>,
        step: fn(&mut EditHistory, &mut crate::scene::Scene) -> crate::Result<Option<usize>>,
    ) -> Option<Arc<RenderContext>> {
        self.drag = None;
        let mut scene = (*ctx.scene).clone();
        let object = step(self.history(ctx), &mut scene).ok()??;
        ctx.with_moved_object(object, Arc::new(scene))
            .ok()
            .map(Arc::new)
    }

    /// One whole move of `object` by `delta` (tests, scripts): the new context.
    pub fn move_object(
        &mut self,
        ctx: &Arc<RenderContext>,
        object: usize,
        delta: Rigid,
    ) -> Option<Arc<RenderContext>> {
        self.history(ctx).begin_drag(object).ok()?;
        let moved = self.update(object, ctx, delta);
        if let Some(h) = &mut self.history {
            h.end_drag();
        }
        moved
    }

    /// A drag driven by a program, as the handles drive one: the first call begins it, each
    /// call moves the object to `delta` after its start; [`SceneEditor::end_scripted_drag`]
    /// ends it.
    pub fn drag_to(
        &mut self,
        ctx: &Arc<RenderContext>,
        object: usize,
        delta: Rigid,
    ) -> Option<Arc<RenderContext>> {
        if self.scripted.is_none() {
            self.history(ctx).begin_drag(object).ok()?;
            self.scripted = Some(ctx.clone());
        }
        let base = self.scripted.clone()?;
        self.update(object, &base, delta)
    }

    pub fn end_scripted_drag(&mut self) {
        if let Some(h) = &mut self.history {
            h.end_drag();
        }
        self.scripted = None;
    }

    /// The pivot of `object` (the centre of its bounding box), where its gizmo is drawn.
    pub fn pivot(&mut self, ctx: &RenderContext, object: usize) -> Option<DVec3> {
        self.history(ctx).pivot(object).ok()
    }

    /// The list of objects, selectable; the selected one's current transform.
    pub(crate) fn list_ui(&mut self, ui: &mut Ui, ctx: &RenderContext) {
        let selected = self.selected;
        for (i, o) in ctx.scene.objects.iter().enumerate() {
            let mut flags = Vec::new();
            if o.flags.light && o.material.is_emissive() {
                flags.push("light");
            }
            if o.flags.occluder {
                flags.push("occluder");
            }
            if o.flags.receiver {
                flags.push("receiver");
            }
            let shape = ctx
                .prepared
                .objects
                .iter()
                .find(|p| p.object == i as u32)
                .map(|p| p.kind().label())
                .unwrap_or("receiver only");
            let text = format!("{}  ·  {}  ·  {}", o.name, flags.join(", "), shape);
            if ui
                .selectable_label(selected == Some(i), text)
                .on_hover_text("Select to move it with the handles in the viewport")
                .clicked()
            {
                self.selected = if selected == Some(i) { None } else { Some(i) };
            }
        }
        if let Some(i) = self.selected
            && let Some(h) = &self.history
            && let Ok(t) = h.transform(i)
        {
            let (axis, angle) = t.axis_angle();
            ui.small(format!(
                "moved by ({:.3}, {:.3}, {:.3}), turned {:.1}° about ({:.2}, {:.2}, {:.2})",
                t.translation.x,
                t.translation.y,
                t.translation.z,
                angle.to_degrees(),
                axis.x,
                axis.y,
                axis.z
            ));
        }
        if let Some(t) = self.last_timing {
            ui.small(format!("last move prepared in {:.1} ms", t.prepare_ms));
        }
    }
}
