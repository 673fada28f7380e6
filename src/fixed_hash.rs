//! Hash maps and sets with a fixed hasher (SipHash-1-3 with zero keys) instead of the standard library's
//! per-process random seed: the engine's lookups then take the same path in every run, so its instruction
//! counts repeat exactly (`cargo perf`) and no iteration order can depend on the seed. No map here holds
//! keys an adversary chooses to collide.

use std::collections::hash_map::DefaultHasher;
use std::hash::BuildHasherDefault;

/// A `HashMap` with the fixed hasher.
pub type FixedHashMap<K, V> = std::collections::HashMap<K, V, BuildHasherDefault<DefaultHasher>>;
/// A `HashSet` with the fixed hasher.
pub type FixedHashSet<T> = std::collections::HashSet<T, BuildHasherDefault<DefaultHasher>>;
