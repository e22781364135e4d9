//! Rigid edits of scene objects: a rigid transform type, drags that are one undo step each,
//! undo and redo (docs/scenes.md, "Editing and saving scenes").
//!
//! Every object's position is a function of its vertices when the history started (its
//! *original* vertices) and one accumulated [`Rigid`] transform: applying an edit, undoing or
//! redoing it writes `transform.apply(original)` into the mesh, never a transform of vertices
//! that were moved already. A scene edited, undone and redone is therefore bit for bit the
//! scene that was edited once, and no rounding drift accumulates over many drags.
//!
//! The workbench's call sequence for a drag (the render context is re-prepared cheaply with
//! [`crate::render::RenderContext::with_moved_object`]):
//!
//! ```text
//! let pivot = history.begin_drag(i)?;                  // mouse down on object i
//! // each frame, with the motion since the mouse went down (relative to the drag's start):
//! history.update_drag(Rigid::rotation_about(pivot, DVec3::Y, angle)?.then(Rigid::translation(t)))?;
//! let scene = Arc::new(history.moved_scene(&base_scene, i)?);
//! ctx = Arc::new(ctx.with_moved_object(i, scene.clone())?);   // then re-probe, restart the render
//! history.end_drag();                                  // mouse up: one undo step
//! base_scene = scene;
//! if let Some(i) = history.undo(&mut base_scene)? { /* re-prepare object i */ }
//! ```

use super::Scene;
use crate::EditError;
use glam::{DMat3, DQuat, DVec3};

/// A rigid motion `p ↦ R p + t` (a rotation, then a translation), in f64.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Rigid {
    /// Unit quaternion of the rotation `R`.
    pub rotation: DQuat,
    pub translation: DVec3,
}

impl Default for Rigid {
    fn default() -> Self {
        Rigid::IDENTITY
    }
}

impl Rigid {
    pub const IDENTITY: Rigid = Rigid {
        rotation: DQuat::IDENTITY,
        translation: DVec3::ZERO,
    };

    /// The translation by `t`.
    pub fn translation(t: DVec3) -> Rigid {
        Rigid {
            rotation: DQuat::IDENTITY,
            translation: t,
        }
    }

    /// The rotation by `angle` radians about `axis` (right-handed) through the origin; an error
    /// for a zero or non-finite axis or angle.
    pub fn rotation(axis: DVec3, angle: f64) -> crate::Result<Rigid> {
        let axis = axis.try_normalize().ok_or(EditError::NotFinite)?;
        if !angle.is_finite() {
            return Err(EditError::NotFinite.into());
        }
        Ok(Rigid {
            rotation: DQuat::from_axis_angle(axis, angle),
            translation: DVec3::ZERO,
        })
    }

    /// The rotation by `angle` radians about the axis through `pivot` along `axis`:
    /// `p ↦ R (p − pivot) + pivot`.
    pub fn rotation_about(pivot: DVec3, axis: DVec3, angle: f64) -> crate::Result<Rigid> {
        if !pivot.is_finite() {
            return Err(EditError::NotFinite.into());
        }
        let r = Rigid::rotation(axis, angle)?;
        Ok(Rigid {
            rotation: r.rotation,
            translation: pivot - r.rotation * pivot,
        })
    }

    /// The rotation matrix `R`.
    pub(crate) fn matrix(&self) -> DMat3 {
        DMat3::from_quat(self.rotation)
    }

    /// `self` applied to the point `p`.
    #[inline]
    pub fn apply(&self, p: DVec3) -> DVec3 {
        self.matrix() * p + self.translation
    }

    /// `self` applied to every point of `points`, written to `out` (cleared first): the matrix
    /// is formed once, so the result depends on `self` and the points alone.
    pub(crate) fn apply_all(&self, points: &[DVec3], out: &mut Vec<DVec3>) {
        let m = self.matrix();
        out.clear();
        out.extend(points.iter().map(|&p| m * p + self.translation));
    }

    /// `self` after `first`: the motion that applies `first`, then `self`. The quaternion is
    /// renormalised so that long chains stay rotations.
    pub fn after(&self, first: &Rigid) -> Rigid {
        Rigid {
            rotation: (self.rotation * first.rotation).normalize(),
            translation: self.rotation * first.translation + self.translation,
        }
    }

    /// `then` after `self`: `self` first, then `then`.
    pub fn then(&self, then: Rigid) -> Rigid {
        then.after(self)
    }

    /// The inverse motion.
    pub fn inverse(&self) -> Rigid {
        let q = self.rotation.inverse();
        Rigid {
            rotation: q,
            translation: -(q * self.translation),
        }
    }

    pub(crate) fn is_finite(&self) -> bool {
        self.rotation.is_finite() && self.translation.is_finite()
    }

    /// The rotation as (unit axis, angle in radians); the axis is +y for no rotation.
    pub fn axis_angle(&self) -> (DVec3, f64) {
        let (axis, angle) = self.rotation.to_axis_angle();
        if angle == 0.0 || !axis.is_finite() {
            (DVec3::Y, 0.0)
        } else {
            (axis, angle)
        }
    }
}

/// One undo step: object `object` went from transform `before` to `after` (both relative to
/// its original vertices).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Edit {
    pub object: usize,
    pub before: Rigid,
    pub after: Rigid,
}

#[derive(Clone, Copy, Debug)]
struct Drag {
    object: usize,
    /// The object's transform when the drag began.
    start: Rigid,
    /// The motion since then (world space).
    delta: Rigid,
    pivot: DVec3,
}

/// The edits of one scene: each object's accumulated transform, the undo and redo stacks and
/// the drag in progress.
#[derive(Clone, Debug, Default)]
pub struct EditHistory {
    originals: Vec<Vec<DVec3>>,
    transforms: Vec<Rigid>,
    undo: Vec<Edit>,
    redo: Vec<Edit>,
    drag: Option<Drag>,
}

/// The index of the object `spec` names: an index (`"3"`), else a name, which must be unique.
pub fn resolve_object(scene: &Scene, spec: &str) -> crate::Result<usize> {
    let count = scene.objects.len();
    if let Ok(index) = spec.trim().parse::<usize>() {
        return if index < count {
            Ok(index)
        } else {
            Err(EditError::ObjectOutOfRange { index, count }.into())
        };
    }
    let found: Vec<usize> = (0..count)
        .filter(|&i| scene.objects[i].name == spec)
        .collect();
    match found.len() {
        0 => Err(EditError::NoSuchObject(spec.to_owned()).into()),
        1 => Ok(found[0]),
        n => Err(EditError::AmbiguousName {
            name: spec.to_owned(),
            count: n,
            indices: found
                .iter()
                .map(|i| i.to_string())
                .collect::<Vec<_>>()
                .join(", "),
        }
        .into()),
    }
}

impl EditHistory {
    /// A history starting at `scene` as it is: its vertices are the originals every transform
    /// applies to.
    pub fn new(scene: &Scene) -> EditHistory {
        EditHistory {
            originals: scene
                .objects
                .iter()
                .map(|o| o.mesh.positions.clone())
                .collect(),
            transforms: vec![Rigid::IDENTITY; scene.objects.len()],
            ..EditHistory::default()
        }
    }

    fn check(&self, object: usize) -> crate::Result<()> {
        let count = self.originals.len();
        if object < count {
            Ok(())
        } else {
            Err(EditError::ObjectOutOfRange {
                index: object,
                count,
            }
            .into())
        }
    }

    /// The object's transform relative to its original vertices, the drag in progress
    /// included.
    pub(crate) fn transform(&self, object: usize) -> crate::Result<Rigid> {
        self.check(object)?;
        Ok(match self.drag {
            Some(d) if d.object == object => d.delta.after(&d.start),
            _ => self.transforms[object],
        })
    }

    /// The point rotations of the object turn about: the centre of its current bounding box
    /// (during a drag of it, the centre when the drag began, so that the pivot stays put).
    pub fn pivot(&self, object: usize) -> crate::Result<DVec3> {
        self.check(object)?;
        if let Some(d) = self.drag.filter(|d| d.object == object) {
            return Ok(d.pivot);
        }
        let t = self.transforms[object];
        let m = t.matrix();
        let (lo, hi) = self.originals[object].iter().fold(
            (DVec3::INFINITY, DVec3::NEG_INFINITY),
            |(lo, hi), &p| {
                let q = m * p + t.translation;
                (lo.min(q), hi.max(q))
            },
        );
        Ok(if lo.x <= hi.x {
            0.5 * (lo + hi)
        } else {
            DVec3::ZERO
        })
    }

    /// Starts dragging `object` (a drag in progress is ended first); returns its pivot.
    pub fn begin_drag(&mut self, object: usize) -> crate::Result<DVec3> {
        self.check(object)?;
        self.end_drag();
        let pivot = self.pivot(object)?;
        self.drag = Some(Drag {
            object,
            start: self.transforms[object],
            delta: Rigid::IDENTITY,
            pivot,
        });
        Ok(pivot)
    }

    /// Sets the drag's motion: `delta` is the whole motion since [`EditHistory::begin_drag`]
    /// (world space, applied after the object's transform at the start), not an increment, so
    /// that the object's position never depends on how many updates there were.
    pub fn update_drag(&mut self, delta: Rigid) -> crate::Result<()> {
        if !delta.is_finite() {
            return Err(EditError::NotFinite.into());
        }
        let d = self.drag.as_mut().ok_or(EditError::NoDrag)?;
        d.delta = delta;
        Ok(())
    }

    /// Ends the drag: its motion becomes one undo step (none for a drag that did not move, or
    /// without a drag). Clears the redo stack when it records a step.
    pub fn end_drag(&mut self) -> Option<Edit> {
        let d = self.drag.take()?;
        let after = d.delta.after(&d.start);
        if d.delta == Rigid::IDENTITY || after == d.start {
            return None;
        }
        self.transforms[d.object] = after;
        let edit = Edit {
            object: d.object,
            before: d.start,
            after,
        };
        self.undo.push(edit);
        self.redo.clear();
        Some(edit)
    }

    /// Abandons the drag; returns the object, whose position is its transform before the drag
    /// again (apply it to the scene).
    pub(crate) fn cancel_drag(&mut self) -> Option<usize> {
        self.drag.take().map(|d| d.object)
    }

    /// One whole edit (a drag of one update): moves `object` by `delta` after its current
    /// transform and applies it to `scene`.
    pub fn edit(
        &mut self,
        scene: &mut Scene,
        object: usize,
        delta: Rigid,
    ) -> crate::Result<Option<Edit>> {
        self.check_scene(scene)?;
        self.begin_drag(object)?;
        if let Err(e) = self.update_drag(delta) {
            self.cancel_drag();
            return Err(e);
        }
        let edit = self.end_drag();
        self.apply(scene, object)?;
        Ok(edit)
    }

    fn check_scene(&self, scene: &Scene) -> crate::Result<()> {
        if scene.objects.len() != self.originals.len() {
            return Err(EditError::SceneMismatch(scene.objects.len()).into());
        }
        Ok(())
    }

    /// Writes the object's current position (the drag in progress included) into `scene`:
    /// its transform applied to its original vertices.
    pub fn apply(&self, scene: &mut Scene, object: usize) -> crate::Result<()> {
        self.check_scene(scene)?;
        let t = self.transform(object)?;
        let original = &self.originals[object];
        let mesh = &mut scene.objects[object].mesh;
        if mesh.positions.len() != original.len() {
            return Err(EditError::SceneMismatch(object).into());
        }
        t.apply_all(original, &mut mesh.positions);
        Ok(())
    }

    /// A copy of `scene` with the object at its current position (for a drag's frame).
    pub fn moved_scene(&self, scene: &Scene, object: usize) -> crate::Result<Scene> {
        let mut s = scene.clone();
        self.apply(&mut s, object)?;
        Ok(s)
    }

    /// Undoes the last edit (a drag in progress is cancelled instead); returns the object that
    /// moved, after writing its position into `scene`.
    pub fn undo(&mut self, scene: &mut Scene) -> crate::Result<Option<usize>> {
        self.check_scene(scene)?;
        if let Some(object) = self.cancel_drag() {
            self.apply(scene, object)?;
            return Ok(Some(object));
        }
        let Some(edit) = self.undo.pop() else {
            return Ok(None);
        };
        self.transforms[edit.object] = edit.before;
        self.redo.push(edit);
        self.apply(scene, edit.object)?;
        Ok(Some(edit.object))
    }

    /// Redoes the last undone edit; returns the object that moved, after writing its position
    /// into `scene`.
    pub fn redo(&mut self, scene: &mut Scene) -> crate::Result<Option<usize>> {
        self.check_scene(scene)?;
        self.end_drag();
        let Some(edit) = self.redo.pop() else {
            return Ok(None);
        };
        self.transforms[edit.object] = edit.after;
        self.undo.push(edit);
        self.apply(scene, edit.object)?;
        Ok(Some(edit.object))
    }

    pub fn can_undo(&self) -> bool {
        self.drag.is_some() || !self.undo.is_empty()
    }

    pub fn can_redo(&self) -> bool {
        !self.redo.is_empty()
    }

    /// The recorded steps, oldest first.
    pub fn undo_steps(&self) -> &[Edit] {
        &self.undo
    }
}

/// One rigid move of one object, as `penumbra edit` and the Python module's `Scene.move` ask
/// for it: rotated by `rotate_y_deg` about +y through `pivot` (the object's own pivot when
/// `None`), then translated. Returns the object's index and the pivot used.
pub fn move_object(
    scene: &mut Scene,
    object: &str,
    translate: DVec3,
    rotate_y_deg: f64,
    pivot: Option<DVec3>,
) -> crate::Result<(usize, DVec3)> {
    let index = resolve_object(scene, object)?;
    let mut history = EditHistory::new(scene);
    let pivot = match pivot {
        Some(p) => p,
        None => history.pivot(index)?,
    };
    let rotation = Rigid::rotation_about(pivot, DVec3::Y, rotate_y_deg.to_radians())?;
    let motion = rotation.then(Rigid::translation(translate));
    history.edit(scene, index, motion)?;
    Ok((index, pivot))
}
