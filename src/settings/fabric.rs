//! A fabric's table, in a fabric file or a scene's `[fabric]`: the simulator's properties
//! (SI units per unit width, the curves as points) beside the fabric's names and its look
//! (`[appearance]`, which the simulator never sees).

use crate::appearance::{Appearance, AppearanceError, Look};
use crate::sim::{Fabric, FabricError, FabricPoints};
use std::path::Path;
use serde::de::{DeserializeSeed, IntoDeserializer, MapAccess, Visitor};
use serde::{Deserialize, Deserializer, Serialize, Serializer};

/// A fabric as a file gives it: the simulator's properties (SI units per unit width, the
/// curves as points) with its name, and in a scene the fabric file it starts from.
#[derive(Debug, Clone, PartialEq)]
pub struct FabricConfig {
    /// Bundled fabric name or path of the fabric file this one starts from.
    pub preset: Option<String>,
    pub name: String,
    pub description: String,
    /// The material's properties, each a key of the fabric table.
    pub properties: FabricPoints,
    /// How the fabric is drawn: `[appearance]` (crate::appearance).
    pub appearance: Appearance,
}

impl FabricConfig {
    /// Validated material for the simulator.
    pub fn to_fabric(&self) -> Result<Fabric, FabricError> {
        self.properties.to_fabric()
    }

    /// The checked look, its texture read; a relative texture path is taken against
    /// `base_dir` (a scene's folder; a fabric file's own paths are made relative to the
    /// working directory as it is read, `appearance::resolve_in_table`).
    pub fn look(&self, base_dir: Option<&Path>) -> Result<Look, AppearanceError> {
        Look::check(&self.appearance, base_dir)
    }
}

/// Written as one table: the names beside the properties.
impl Serialize for FabricConfig {
    fn serialize<S: Serializer>(&self, serializer: S) -> Result<S::Ok, S::Error> {
        #[derive(Serialize)]
        struct Table<'a> {
            #[serde(skip_serializing_if = "Option::is_none")]
            preset: &'a Option<String>,
            name: &'a str,
            description: &'a str,
            #[serde(flatten)]
            properties: &'a FabricPoints,
            #[serde(skip_serializing_if = "Appearance::is_empty")]
            appearance: &'a Appearance,
        }
        Table { preset: &self.preset, name: &self.name, description: &self.description, properties: &self.properties, appearance: &self.appearance }
            .serialize(serializer)
    }
}

/// Read as one table: the three names and the appearance are taken out as the keys go by
/// and every other key goes to the properties, so that an error there keeps its key's path (serde's `flatten`
/// would buffer the table and lose it, and cannot refuse unknown keys).
impl<'de> Deserialize<'de> for FabricConfig {
    fn deserialize<D: Deserializer<'de>>(deserializer: D) -> Result<Self, D::Error> {
        struct Fields;
        impl<'de> Visitor<'de> for Fields {
            type Value = FabricConfig;
            fn expecting(&self, f: &mut std::fmt::Formatter) -> std::fmt::Result {
                f.write_str("a table of fabric properties")
            }
            fn visit_map<A: MapAccess<'de>>(self, map: A) -> Result<FabricConfig, A::Error> {
                let mut names = Names::default();
                let properties = FabricPoints::deserialize(serde::de::value::MapAccessDeserializer::new(WithoutNames { map, names: &mut names }))?;
                Ok(FabricConfig {
                    preset: names.preset,
                    name: names.name.unwrap_or_default(),
                    description: names.description.unwrap_or_default(),
                    properties,
                    appearance: names.appearance.unwrap_or_default(),
                })
            }
        }
        #[derive(Default)]
        struct Names {
            preset: Option<String>,
            name: Option<String>,
            description: Option<String>,
            appearance: Option<Appearance>,
        }
        struct WithoutNames<'n, A> {
            map: A,
            names: &'n mut Names,
        }
        impl<'de, A: MapAccess<'de>> MapAccess<'de> for WithoutNames<'_, A> {
            type Error = A::Error;
            fn next_key_seed<K: DeserializeSeed<'de>>(&mut self, seed: K) -> Result<Option<K::Value>, A::Error> {
                while let Some(key) = self.map.next_key::<String>()? {
                    match key.as_str() {
                        "preset" => self.names.preset = Some(self.map.next_value()?),
                        "name" => self.names.name = Some(self.map.next_value()?),
                        "description" => self.names.description = Some(self.map.next_value()?),
                        "appearance" => self.names.appearance = Some(self.map.next_value()?),
                        _ => return seed.deserialize(IntoDeserializer::<A::Error>::into_deserializer(key)).map(Some),
                    }
                }
                Ok(None)
            }
            fn next_value_seed<V: DeserializeSeed<'de>>(&mut self, seed: V) -> Result<V::Value, A::Error> {
                self.map.next_value_seed(seed)
            }
        }
        deserializer.deserialize_map(Fields)
    }
}

/// Sets `key` of a fabric table to `value`, as a scene's own `[fabric]` keys and `--set
/// fabric.KEY` are laid over the fabric file's: a value replaces the file's, except that
/// `[appearance]` is laid over key by key (`--set fabric.appearance.colour=…` keeps the
/// file's weave, print and sheen).
pub fn lay_over(fabric: &mut toml::Table, key: String, value: toml::Value) {
    fn merge(into: &mut toml::Table, from: toml::Table) {
        for (k, v) in from {
            match (into.get_mut(&k), v) {
                (Some(toml::Value::Table(inner)), toml::Value::Table(v)) => merge(inner, v),
                (_, v) => {
                    into.insert(k, v);
                }
            }
        }
    }
    match (fabric.get_mut(&key), value) {
        (Some(toml::Value::Table(file)), toml::Value::Table(scene)) if key == "appearance" => merge(file, scene),
        (_, value) => {
            fabric.insert(key, value);
        }
    }
}
