//! Where each value of a scene came from: the schema's default, a bundled scene (or the
//! scene a pattern import writes), or the user (a scene file of their own, a `--set`, a
//! flag). The run plan may choose its own value over a default or a bundled one, and says
//! so; a value the user set stands (docs/scenes.md, "What the plan changes").

use std::collections::BTreeMap;

/// Who gave a value.
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord)]
pub enum Origin {
    /// Nobody: the schema's default.
    Default,
    /// A bundled scene or fabric, or the scene a pattern import made.
    Bundled,
    /// The user: their own scene or fabric file, a `--set`, a flag.
    User,
}

impl Origin {
    pub fn name(self) -> &'static str {
        match self {
            Self::Default => "the default",
            Self::Bundled => "the bundled scene",
            Self::User => "yours",
        }
    }
}

/// The origin of every key given, by dotted key (`solver.newton.max_iterations`). A key
/// not listed is a default. A table given whole gives each of its keys; an array (props,
/// panels) is one key.
#[derive(Debug, Clone, Default, PartialEq, Eq)]
pub struct Origins {
    given: BTreeMap<String, Origin>,
}

impl Origins {
    /// Who gave `key` (dotted). A key inside an array of tables (`garment.panels[1].grain_deg`)
    /// counts under its array.
    pub fn of(&self, key: &str) -> Origin {
        let key = without_indices(key);
        let mut prefix = key.as_str();
        loop {
            if let Some(origin) = self.given.get(prefix) {
                return *origin;
            }
            match prefix.rfind('.') {
                Some(i) => prefix = &prefix[..i],
                None => return Origin::Default,
            }
        }
    }

    /// Whether the user gave `key`.
    pub fn by_user(&self, key: &str) -> bool {
        self.of(key) == Origin::User
    }

    /// Records every leaf of `table` (under `prefix`) as given by `origin`, over what an
    /// earlier, weaker source gave.
    pub fn record_table(&mut self, prefix: &str, table: &toml::Table, origin: Origin) {
        for (key, value) in table {
            let dotted = if prefix.is_empty() { key.clone() } else { format!("{prefix}.{key}") };
            match value {
                toml::Value::Table(inner) => self.record_table(&dotted, inner, origin),
                _ => self.record(&dotted, origin),
            }
        }
    }

    /// Records `key` (dotted; an array entry's index is kept out) as given by `origin`.
    pub fn record(&mut self, key: &str, origin: Origin) {
        let entry = self.given.entry(without_indices(key)).or_insert(origin);
        *entry = (*entry).max(origin);
    }
}

/// `key` with its array entries' indices left out: `garment.panels[1].grain_deg` is
/// `garment.panels.grain_deg`.
fn without_indices(key: &str) -> String {
    key.split('.').map(|part| part.split('[').next().unwrap_or(part)).collect::<Vec<_>>().join(".")
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_key_is_the_strongest_origin_that_gave_it_or_its_table() {
        let mut origins = Origins::default();
        let table: toml::Table = "[solver]\ndt = 0.004\n[solver.newton]\nmax_iterations = 100\n".parse().unwrap();
        origins.record_table("", &table, Origin::Bundled);
        origins.record("solver.newton.max_iterations", Origin::User);
        origins.record("garment.panels[1].grain_deg", Origin::User);
        assert_eq!(origins.of("solver.dt"), Origin::Bundled);
        assert_eq!(origins.of("solver.newton.max_iterations"), Origin::User);
        assert_eq!(origins.of("solver.newton.tolerance"), Origin::Default);
        assert_eq!(origins.of("solver.path"), Origin::Default);
        assert!(origins.by_user("garment.panels[3].grain_deg"));
        // A bundled value does not take back what the user gave.
        origins.record("solver.newton.max_iterations", Origin::Bundled);
        assert!(origins.by_user("solver.newton.max_iterations"));
    }
}
