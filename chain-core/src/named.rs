//! [`NameMap`]: named values serialised as one ordered object.
//!
//! Result documents list per-variable or per-error values as JSON objects
//! (`{"x": 1.0, "y": 2.0}`) in the model's order, while the results hold them
//! as vectors beside a list of names. `NameMap` pairs the two for serde
//! without building a map: it serialises its pairs, in order, as map entries
//! (duplicate names are the caller's concern; the documents never have any).

use serde::ser::{Serialize, SerializeMap, Serializer};

/// Pairs `(name, value)` serialised as an object, in the order given.
#[derive(Debug, Clone, PartialEq)]
pub struct NameMap<K, V>(pub Vec<(K, V)>);

impl<K, V> NameMap<K, V> {
    /// Pairs `names[i]` with `values[i]` (as many pairs as the shorter has items).
    pub fn zip<I, J>(names: I, values: J) -> NameMap<K, V>
    where
        I: IntoIterator<Item = K>,
        J: IntoIterator<Item = V>,
    {
        NameMap(names.into_iter().zip(values).collect())
    }
}

impl<K, V> FromIterator<(K, V)> for NameMap<K, V> {
    fn from_iter<T: IntoIterator<Item = (K, V)>>(iter: T) -> Self {
        NameMap(iter.into_iter().collect())
    }
}

impl<K: Serialize, V: Serialize> Serialize for NameMap<K, V> {
    fn serialize<S: Serializer>(&self, serializer: S) -> Result<S::Ok, S::Error> {
        let mut map = serializer.serialize_map(Some(self.0.len()))?;
        for (k, v) in &self.0 {
            map.serialize_entry(k, v)?;
        }
        map.end()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn pairs_serialise_as_an_object_in_their_order() {
        let m = NameMap::zip(["z", "a"], [1.5, f64::NAN]);
        assert_eq!(serde_json::to_string(&m).unwrap(), r#"{"z":1.5,"a":null}"#);
        let empty: NameMap<&str, f64> = NameMap(Vec::new());
        assert_eq!(serde_json::to_string(&empty).unwrap(), "{}");
    }
}
