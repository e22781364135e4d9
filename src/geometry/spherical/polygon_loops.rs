use glam::DVec3;

/// Storage for a set of closed vertex loops, shared by [`SphericalPolygon`](crate::geometry::SphericalPolygon)
/// and [`PlanarPolygon`](crate::geometry::PlanarPolygon). The vertices of all loops live in one buffer so that
/// clearing and refilling it in the hot loop never allocates once its capacity has grown.
///
/// A loop is closed implicitly: its last vertex connects back to its first.
#[derive(Clone, Debug, Default, PartialEq, serde::Serialize, serde::Deserialize)]
#[serde(try_from = "StoredLoops")]
pub struct PolygonLoops {
    vertices: Vec<DVec3>,
    /// `loop_ends[i]` is one past the last vertex of loop `i`.
    loop_ends: Vec<u32>,
}

/// [`PolygonLoops`] as read from a file (a debug dump), before its loop ends are checked.
#[derive(serde::Deserialize)]
struct StoredLoops {
    vertices: Vec<DVec3>,
    loop_ends: Vec<u32>,
}

impl TryFrom<StoredLoops> for PolygonLoops {
    type Error = crate::Error;

    /// Loop ends must not decrease and the last must be the vertex count, so that every loop
    /// is a slice of the vertices.
    fn try_from(s: StoredLoops) -> crate::Result<Self> {
        let ordered = s.loop_ends.windows(2).all(|w| w[0] <= w[1]);
        let last = s.loop_ends.last().map_or(0, |&e| e as usize);
        if !ordered || last != s.vertices.len() {
            return Err(crate::Error::from(format!(
                "polygon loop ends {:?} do not split its {} vertices",
                &s.loop_ends[..s.loop_ends.len().min(8)],
                s.vertices.len()
            )));
        }
        Ok(PolygonLoops {
            vertices: s.vertices,
            loop_ends: s.loop_ends,
        })
    }
}

impl PolygonLoops {
    pub fn new() -> Self {
        Self::default()
    }

    /// Removes every loop, keeping the capacity.
    #[inline]
    pub(crate) fn clear(&mut self) {
        self.vertices.clear();
        self.loop_ends.clear();
    }

    #[inline]
    pub fn is_empty(&self) -> bool {
        self.loop_ends.is_empty()
    }

    #[inline]
    pub fn loop_count(&self) -> usize {
        self.loop_ends.len()
    }

    #[inline]
    pub fn vertex_count(&self) -> usize {
        self.vertices.len()
    }

    /// All vertices of all loops, loop after loop.
    #[inline]
    pub fn vertices(&self) -> &[DVec3] {
        &self.vertices
    }

    /// Loop `i` as a slice of its vertices.
    #[inline]
    pub fn loop_at(&self, i: usize) -> &[DVec3] {
        let start = if i == 0 {
            0
        } else {
            self.loop_ends[i - 1] as usize
        };
        &self.vertices[start..self.loop_ends[i] as usize]
    }

    /// Iterates over the loops.
    pub fn loops(&self) -> impl ExactSizeIterator<Item = &[DVec3]> + '_ {
        (0..self.loop_ends.len()).map(move |i| self.loop_at(i))
    }

    /// Appends a vertex to the loop under construction (see [`PolygonLoops::close_loop`]).
    #[inline]
    pub(crate) fn push_vertex(&mut self, v: DVec3) {
        self.vertices.push(v);
    }

    /// Number of vertices pushed since the last closed loop.
    #[inline]
    pub(crate) fn open_loop_len(&self) -> usize {
        self.vertices.len() - self.loop_ends.last().copied().unwrap_or(0) as usize
    }

    /// The vertices pushed since the last closed loop.
    #[inline]
    pub(crate) fn open_loop(&self) -> &[DVec3] {
        let start = self.loop_ends.last().copied().unwrap_or(0) as usize;
        &self.vertices[start..]
    }

    /// Closes the loop under construction. Loops with fewer than three vertices bound no area
    /// and are discarded. Returns whether a loop was added.
    #[inline]
    pub(crate) fn close_loop(&mut self) -> bool {
        let n = self.open_loop_len();
        if n >= 3 {
            self.loop_ends.push(self.vertices.len() as u32);
            true
        } else {
            self.discard_open_loop();
            false
        }
    }

    /// Drops the vertices pushed since the last closed loop.
    #[inline]
    pub(crate) fn discard_open_loop(&mut self) {
        let start = self.loop_ends.last().copied().unwrap_or(0) as usize;
        self.vertices.truncate(start);
    }

    /// Drops the last vertex of the open loop (`n` = current vertex count, for the caller's check).
    #[inline]
    pub(crate) fn discard_last_vertex(&mut self, n: usize) {
        debug_assert_eq!(n, self.vertices.len());
        self.vertices.pop();
    }

    /// Appends a whole loop.
    pub fn push_loop(&mut self, vertices: impl IntoIterator<Item = DVec3>) -> bool {
        for v in vertices {
            self.push_vertex(v);
        }
        self.close_loop()
    }

    /// Appends all loops of `other`.
    pub(crate) fn extend_from(&mut self, other: &PolygonLoops) {
        let offset = self.vertices.len() as u32;
        self.vertices.extend_from_slice(&other.vertices);
        self.loop_ends
            .extend(other.loop_ends.iter().map(|e| e + offset));
    }

    /// Replaces the contents with a copy of `other`, reusing the capacity.
    pub fn copy_from(&mut self, other: &PolygonLoops) {
        self.clear();
        self.extend_from(other);
    }

    /// Applies `f` to every vertex in place.
    pub fn map_vertices(&mut self, mut f: impl FnMut(DVec3) -> DVec3) {
        for v in &mut self.vertices {
            *v = f(*v);
        }
    }

    /// Reverses the orientation of every loop.
    pub(crate) fn reverse_loops(&mut self) {
        let mut start = 0usize;
        for &end in &self.loop_ends {
            self.vertices[start..end as usize].reverse();
            start = end as usize;
        }
    }
}
