//! The exact-distance indexes alive: the `program` estimators of one path share one
//! index, and a restored estimator finds its index instead of building it again (the
//! infinity NURBS's takes 1.3 ms, a long program's longer). Whoever owns the instances
//! owns the cache (the FMU library one per process), as with the plans.

use std::sync::Arc;

use super::TrueErrorIndex;
use crate::path::planar::Path;
use crate::shared::Shared;

/// Builds [`TrueErrorIndex`]es, keeping each while an estimator holds it, and the one used
/// last.
#[derive(Debug, Default)]
pub struct TrueErrorIndexes(Shared<Path, TrueErrorIndex>);

impl TrueErrorIndexes {
    /// An empty cache.
    pub fn new() -> Self {
        TrueErrorIndexes::default()
    }

    /// How many indexes were built, not found kept.
    pub fn indexes_made(&self) -> u64 {
        self.0.made()
    }

    /// The index of `path`, kept or built now.
    pub fn index(&self, path: &Path) -> Arc<TrueErrorIndex> {
        let made = self.0.get_or_make(
            |p| p == path,
            || path.clone(),
            || Ok::<_, std::convert::Infallible>(TrueErrorIndex::new(path)),
        );
        match made {
            Ok(index) => index,
            Err(never) => match never {},
        }
    }
}
