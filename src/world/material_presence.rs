//! Which materials the bodies of a world use, kept up to date as bodies are added, so that the check of a
//! new body's material (a law with every material already present) costs one look-up per distinct
//! material instead of one per body: setting up N bodies of M materials is O(N·M), not O(N²).
//!
//! The table follows appends to [`super::World::material_of`]: on each check it first records the bodies
//! added since the last one. A world read from a checkpoint starts with an empty table and records all its
//! bodies at its first check. Walls are few (the planes of a box) and are read afresh at each check.

/// What the set-up checks of a world did: counts of work, for tests and benchmarks that show set-up
/// grows linearly with the number of bodies.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct SetupStats {
    /// Material-pair law look-ups made by the checks of added bodies and walls.
    pub law_lookups: u64,
    /// Body materials recorded into the presence table (one per body, once).
    pub bodies_recorded: u64,
    /// Wall materials read by the checks of added bodies.
    pub walls_read: u64,
}

impl SetupStats {
    /// All the work counted: look-ups plus records plus reads.
    pub fn total(&self) -> u64 {
        self.law_lookups + self.bodies_recorded + self.walls_read
    }
}

/// For each material id, the first body (in insertion order) that uses it; the prefix of bodies recorded.
#[derive(Clone, Debug, Default)]
pub(crate) struct MaterialPresence {
    first_body: Vec<Option<usize>>,
    /// Materials present among the recorded bodies, in order of their first body.
    present: Vec<u32>,
    recorded: usize,
    pub stats: SetupStats,
}

impl MaterialPresence {
    /// Records the bodies of `material_of` added since the last call (all of them if the list shrank).
    pub fn record(&mut self, material_of: &[u32]) {
        if self.recorded > material_of.len() {
            let stats = self.stats;
            *self = Self {
                stats,
                ..Self::default()
            };
        }
        for (i, &m) in material_of.iter().enumerate().skip(self.recorded) {
            let m = m as usize;
            if m >= self.first_body.len() {
                self.first_body.resize(m + 1, None);
            }
            if self.first_body[m].is_none() {
                self.first_body[m] = Some(i);
                self.present.push(m as u32);
            }
            self.stats.bodies_recorded += 1;
        }
        self.recorded = material_of.len();
    }

    /// The materials of the recorded bodies, in the order of the first body of each: the order in which a
    /// scan of every body meets them.
    pub fn present(&self) -> &[u32] {
        &self.present
    }
}
