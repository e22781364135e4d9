//! What one shading point keeps of each occluder for its next lights. 000 Alg. 1 subtracts an
//! occluder from every light it lies in front of, and the occluder's outline as a whole depends
//! on the point alone: found once, projected once. Kept per occluder: the projected,
//! horizon-clipped outline, and a convex outline as found before a light's window clipped it.
//!
//! A stamp per point makes everything kept stale at once, without clearing a buffer. Recording
//! is a policy of the cache: while a recorder is on (`R::ENABLED`) nothing is kept or lent, so
//! that every stage runs again for every light and reaches the recording, with the same
//! numbers.

use crate::geometry::{PlanarPolygon, SphericalPolygon};
use crate::shading::Recorder;

/// The occluders kept at the current shading point.
#[derive(Default)]
pub(crate) struct OccluderCache {
    entries: Vec<Kept>,
    /// Counts shading points: an entry is current when it was kept at this one.
    stamp: u64,
}

#[derive(Default)]
struct Kept {
    projected_at: u64,
    projected: PlanarPolygon,
    outline_at: u64,
    outline: SphericalPolygon,
}

impl OccluderCache {
    /// A new shading point in a scene of `occluders` occluders: everything kept is stale.
    pub(crate) fn begin_point(&mut self, occluders: usize) {
        self.stamp += 1;
        if self.entries.len() < occluders {
            self.entries.resize_with(occluders, Kept::default);
        }
    }

    /// Lends occluder `oi`'s projected outline kept at this point by trading it for `slot`'s
    /// buffer; `false` (and `slot` untouched) when none is kept. Return it with
    /// [`OccluderCache::take_back`] before anything else is kept.
    pub(crate) fn lend_projected<R: Recorder>(
        &mut self,
        oi: usize,
        slot: &mut PlanarPolygon,
    ) -> bool {
        let current = !R::ENABLED && self.entries[oi].projected_at == self.stamp;
        if current {
            std::mem::swap(slot, &mut self.entries[oi].projected);
        }
        current
    }

    /// Takes back what [`OccluderCache::lend_projected`] lent, and gives `slot` its buffer.
    pub(crate) fn take_back(&mut self, oi: usize, slot: &mut PlanarPolygon) {
        std::mem::swap(slot, &mut self.entries[oi].projected);
    }

    /// Copies occluder `oi`'s projected outline kept at this point into `out`; `false` when
    /// none is kept.
    pub(crate) fn copy_projected<R: Recorder>(&self, oi: usize, out: &mut PlanarPolygon) -> bool {
        let current = !R::ENABLED && self.entries[oi].projected_at == self.stamp;
        if current {
            out.copy_from(&self.entries[oi].projected);
        }
        current
    }

    /// Keeps `slot` as occluder `oi`'s projected outline at this point, trading buffers (what
    /// `slot` holds afterwards is stale).
    pub(crate) fn keep_projected<R: Recorder>(&mut self, oi: usize, slot: &mut PlanarPolygon) {
        if !R::ENABLED {
            let kept = &mut self.entries[oi];
            std::mem::swap(slot, &mut kept.projected);
            kept.projected_at = self.stamp;
        }
    }

    /// Copies occluder `oi`'s whole outline kept at this point into `out`; `false` when none
    /// is kept.
    pub(crate) fn copy_outline<R: Recorder>(&self, oi: usize, out: &mut SphericalPolygon) -> bool {
        let current = !R::ENABLED && self.entries[oi].outline_at == self.stamp;
        if current {
            out.0.copy_from(&self.entries[oi].outline.0);
        }
        current
    }

    /// Keeps a copy of `outline` as occluder `oi`'s whole outline at this point.
    pub(crate) fn keep_outline<R: Recorder>(&mut self, oi: usize, outline: &SphericalPolygon) {
        if !R::ENABLED {
            let kept = &mut self.entries[oi];
            kept.outline.0.copy_from(&outline.0);
            kept.outline_at = self.stamp;
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::shading::{NoRecorder, StageRecording};
    use glam::DVec3;

    fn polygon(z: f64) -> SphericalPolygon {
        let mut p = SphericalPolygon::default();
        p.0.push_loop([
            DVec3::new(1.0, 0.0, z).normalize(),
            DVec3::new(0.0, 1.0, z).normalize(),
            DVec3::new(-1.0, -1.0, z).normalize(),
        ]);
        p
    }

    /// What is kept at a point is lent and copied at that point only; a new point finds
    /// nothing kept.
    #[test]
    fn kept_for_one_point_only() {
        let mut cache = OccluderCache::default();
        cache.begin_point(2);
        let mut out = SphericalPolygon::default();
        assert!(!cache.copy_outline::<NoRecorder>(1, &mut out));
        let kept = polygon(0.5);
        cache.keep_outline::<NoRecorder>(1, &kept);
        assert!(cache.copy_outline::<NoRecorder>(1, &mut out));
        assert_eq!(out.0.vertex_count(), 3);
        assert!(!cache.copy_outline::<NoRecorder>(0, &mut out));
        cache.begin_point(2);
        assert!(!cache.copy_outline::<NoRecorder>(1, &mut out));
    }

    /// A lent projection comes back to the cache, and the slot gets its own buffer back.
    #[test]
    fn lending_trades_buffers_and_back() {
        let mut cache = OccluderCache::default();
        cache.begin_point(1);
        let mut slot = PlanarPolygon::default();
        assert!(!cache.lend_projected::<NoRecorder>(0, &mut slot));
        slot.push_loop([DVec3::X, DVec3::Y, DVec3::Z]);
        cache.keep_projected::<NoRecorder>(0, &mut slot);
        let mut other = PlanarPolygon::default();
        assert!(cache.lend_projected::<NoRecorder>(0, &mut other));
        assert_eq!(other.vertex_count(), 3);
        cache.take_back(0, &mut other);
        assert_eq!(other.vertex_count(), 0);
        let mut copy = PlanarPolygon::default();
        assert!(cache.copy_projected::<NoRecorder>(0, &mut copy));
        assert_eq!(copy.vertex_count(), 3);
    }

    /// With a recorder on, nothing is kept: every light finds the outline again.
    #[test]
    fn recording_keeps_nothing() {
        let mut cache = OccluderCache::default();
        cache.begin_point(1);
        cache.keep_outline::<StageRecording>(0, &polygon(0.5));
        let mut out = SphericalPolygon::default();
        assert!(!cache.copy_outline::<StageRecording>(0, &mut out));
        assert!(!cache.copy_outline::<NoRecorder>(0, &mut out));
    }
}
