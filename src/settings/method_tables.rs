//! The methods' own settings (`[methods.<cli name>]` tables): kept as the TOML table a user
//! wrote (saved, compared and edited by `--set` as such) beside the method's typed struct,
//! parsed the first time the method asks for it and again only after the table changes. A
//! clone shares the parsed struct, so the renderer's per-frame copies parse nothing (issue 38:
//! "parsed when they change, not per frame").

use std::any::Any;
use std::collections::BTreeMap;
use std::fmt;
use std::sync::{Arc, OnceLock};

use serde::de::DeserializeOwned;
use serde::{Deserialize, Deserializer, Serialize, Serializer};

/// A parsed table: the method's struct, or the message of why it does not parse.
type Parsed = Result<Arc<dyn Any + Send + Sync>, String>;

struct Entry {
    raw: toml::Table,
    parsed: OnceLock<Parsed>,
}

impl Entry {
    fn new(raw: toml::Table) -> Self {
        Self {
            raw,
            parsed: OnceLock::new(),
        }
    }
}

impl Clone for Entry {
    fn clone(&self) -> Self {
        let parsed = OnceLock::new();
        if let Some(p) = self.parsed.get() {
            let _ = parsed.set(p.clone());
        }
        Self {
            raw: self.raw.clone(),
            parsed,
        }
    }
}

/// The `[methods.*]` tables by method CLI name.
#[derive(Clone, Default)]
pub struct MethodTables(BTreeMap<String, Entry>);

impl MethodTables {
    pub fn is_empty(&self) -> bool {
        self.0.is_empty()
    }

    /// The tables' names.
    pub fn keys(&self) -> impl Iterator<Item = &String> {
        self.0.keys()
    }

    /// The table as written (None where absent).
    pub fn raw(&self, key: &str) -> Option<&toml::Table> {
        self.0.get(key).map(|e| &e.raw)
    }

    /// The table `key` as a `T` (its defaults where absent), parsed once per change of the
    /// table; the error names the table and the field.
    pub fn get<T: DeserializeOwned + Default + Clone + Send + Sync + 'static>(
        &self,
        key: &str,
    ) -> Result<T, String> {
        let Some(e) = self.0.get(key) else {
            return Ok(T::default());
        };
        let parse = || -> Parsed {
            e.raw
                .clone()
                .try_into::<T>()
                .map(|t| Arc::new(t) as Arc<dyn Any + Send + Sync>)
                .map_err(|err| format!("methods.{key}: {}", err.message()))
        };
        match e.parsed.get_or_init(parse) {
            Ok(any) => match any.downcast_ref::<T>() {
                Some(t) => Ok(t.clone()),
                // Read as another type than the first reader's (a test's own struct): parse
                // again, uncached.
                None => parse().map(|a| a.downcast_ref::<T>().cloned().unwrap_or_default()),
            },
            Err(m) => Err(m.clone()),
        }
    }

    /// Stores `value` as the table `key`: the keys where it differs from `T`'s defaults (none:
    /// no table), as a user would write it, so that settings equal in value compare equal
    /// however they were reached.
    pub fn set<T: Serialize + Default>(&mut self, key: &str, value: &T) -> Result<(), String> {
        let t = toml::Table::try_from(value).map_err(|e| format!("methods.{key}: {e}"))?;
        let d = toml::Table::try_from(T::default()).map_err(|e| format!("methods.{key}: {e}"))?;
        let t = diff(&t, &d);
        if t.is_empty() {
            self.0.remove(key);
        } else {
            self.insert_raw(key, t);
        }
        Ok(())
    }

    /// Stores the table `key` as written.
    pub fn insert_raw(&mut self, key: &str, table: toml::Table) {
        self.0.insert(key.to_string(), Entry::new(table));
    }

    /// Removes the table `key`, returning it as written.
    pub fn remove(&mut self, key: &str) -> Option<toml::Table> {
        self.0.remove(key).map(|e| e.raw)
    }
}

/// The keys of `value` that differ from `default` (nested tables key by key).
fn diff(value: &toml::Table, default: &toml::Table) -> toml::Table {
    let mut out = toml::Table::new();
    for (k, v) in value {
        match (v, default.get(k)) {
            (toml::Value::Table(a), Some(toml::Value::Table(b))) => {
                let d = diff(a, b);
                if !d.is_empty() {
                    out.insert(k.clone(), toml::Value::Table(d));
                }
            }
            (v, Some(dv)) if v == dv => {}
            _ => {
                out.insert(k.clone(), v.clone());
            }
        }
    }
    out
}

impl PartialEq for MethodTables {
    fn eq(&self, other: &Self) -> bool {
        self.0.len() == other.0.len()
            && self
                .0
                .iter()
                .zip(&other.0)
                .all(|((ka, a), (kb, b))| ka == kb && a.raw == b.raw)
    }
}

impl fmt::Debug for MethodTables {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.debug_map()
            .entries(self.0.iter().map(|(k, e)| (k, &e.raw)))
            .finish()
    }
}

impl Serialize for MethodTables {
    fn serialize<S: Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        s.collect_map(self.0.iter().map(|(k, e)| (k, &e.raw)))
    }
}

impl<'de> Deserialize<'de> for MethodTables {
    fn deserialize<D: Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        let m = BTreeMap::<String, toml::Table>::deserialize(d)?;
        Ok(Self(m.into_iter().map(|(k, t)| (k, Entry::new(t))).collect()))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
    #[serde(default, deny_unknown_fields)]
    struct Knobs {
        cap: u32,
    }

    #[test]
    fn a_table_is_parsed_once_and_again_after_it_changes_and_clones_share_it() {
        let mut m = MethodTables::default();
        assert_eq!(m.get::<Knobs>("x"), Ok(Knobs::default()));
        m.set("x", &Knobs { cap: 3 }).unwrap();
        assert_eq!(m.get::<Knobs>("x"), Ok(Knobs { cap: 3 }));
        let first = m.0["x"].parsed.get().unwrap().as_ref().unwrap().clone();
        let c = m.clone();
        let shared = c.0["x"].parsed.get().unwrap().as_ref().unwrap().clone();
        assert!(Arc::ptr_eq(&first, &shared), "a clone shares the parsed struct");
        assert_eq!(c, m);
        m.set("x", &Knobs { cap: 4 }).unwrap();
        assert_eq!(m.get::<Knobs>("x"), Ok(Knobs { cap: 4 }));
        assert_ne!(c, m);
        // The defaults are no table: equal to never having set one.
        m.set("x", &Knobs::default()).unwrap();
        assert!(m.raw("x").is_none() && m == MethodTables::default());
        let mut bad = toml::Table::new();
        bad.insert("cap".into(), toml::Value::String("many".into()));
        m.insert_raw("x", bad);
        let e = m.get::<Knobs>("x").unwrap_err();
        assert!(e.contains("methods.x"), "{e}");
    }
}
