//! Strict shapes for spec tables: a table given as an array (or as any other shape) is an error
//! naming the key.
//!
//! serde's derived structs accept a sequence of their fields in order as well as a table, so
//! through the toml crate `surface = [1.0, 2.0]` would read as `mu = 1.0, temperature_c = 2.0`
//! and `integrator = ["rk4", 0.01]` as a method and a step. [`check`] deserializes the parsed
//! value a second time through `Strict`, a deserializer of `toml::Value` that hands a struct
//! only a table, and reports a shape error with the key's dotted path. Every other question
//! (types, ranges, unknown keys) is the first, ordinary parse's.

use std::path::Path;

use serde::de::{self, value::Error as DeError, Deserializer, IntoDeserializer, Visitor};

use vehsim_core::error::{Error, Result};

/// Text that marks the shape errors of [`Strict`] (only those are reported by [`check`]).
pub(crate) const MARK: &str = "expected a table";

/// A `toml::Value` seen as a deserializer that gives a struct only a table.
#[derive(Clone, Copy)]
pub(crate) struct Strict<'a>(pub &'a toml::Value);

impl<'de> Deserializer<'de> for Strict<'_> {
    type Error = DeError;

    fn deserialize_any<V: Visitor<'de>>(self, v: V) -> std::result::Result<V::Value, DeError> {
        match self.0 {
            toml::Value::String(s) => v.visit_str(s),
            toml::Value::Integer(i) => v.visit_i64(*i),
            toml::Value::Float(f) => v.visit_f64(*f),
            toml::Value::Boolean(b) => v.visit_bool(*b),
            toml::Value::Datetime(d) => v.visit_string(d.to_string()),
            toml::Value::Array(a) => v.visit_seq(de::value::SeqDeserializer::new(a.iter().map(Strict))),
            toml::Value::Table(t) => {
                v.visit_map(de::value::MapDeserializer::new(t.iter().map(|(k, x)| (k.as_str(), Strict(x)))))
            }
        }
    }

    fn deserialize_struct<V: Visitor<'de>>(
        self,
        _name: &'static str,
        _fields: &'static [&'static str],
        v: V,
    ) -> std::result::Result<V::Value, DeError> {
        match self.0 {
            toml::Value::Table(_) => self.deserialize_any(v),
            other => Err(de::Error::custom(format!(
                "{MARK} of keys (a [section] or {{ key = value }}), found {} {}",
                article(other.type_str()),
                other.type_str()
            ))),
        }
    }

    fn deserialize_option<V: Visitor<'de>>(self, v: V) -> std::result::Result<V::Value, DeError> {
        v.visit_some(self)
    }

    fn deserialize_newtype_struct<V: Visitor<'de>>(
        self,
        _name: &'static str,
        v: V,
    ) -> std::result::Result<V::Value, DeError> {
        v.visit_newtype_struct(self)
    }

    fn deserialize_enum<V: Visitor<'de>>(
        self,
        _name: &'static str,
        _variants: &'static [&'static str],
        v: V,
    ) -> std::result::Result<V::Value, DeError> {
        match self.0 {
            toml::Value::String(s) => v.visit_enum(s.as_str().into_deserializer()),
            _ => self.deserialize_any(v),
        }
    }

    serde::forward_to_deserialize_any! {
        bool i8 i16 i32 i64 i128 u8 u16 u32 u64 u128 f32 f64 char str string bytes byte_buf unit
        unit_struct seq tuple tuple_struct map identifier ignored_any
    }
}

impl<'de, 'a> IntoDeserializer<'de, DeError> for Strict<'a> {
    type Deserializer = Strict<'a>;
    fn into_deserializer(self) -> Self {
        self
    }
}

fn article(word: &str) -> &'static str {
    if word.starts_with(['a', 'e', 'i', 'o', 'u']) {
        "an"
    } else {
        "a"
    }
}

/// Bad input when `value` (read from `path`) gives a table of `T` in another shape: the key's
/// dotted path, what was found and that a table is expected. Other mismatches are left to the
/// ordinary parse, which reports them with its own messages.
pub fn check<T: serde::de::DeserializeOwned>(path: &Path, value: &toml::Value) -> Result<()> {
    match serde_path_to_error::deserialize::<_, T>(Strict(value)) {
        Err(e) if e.inner().to_string().contains(MARK) => {
            let key = e.path().to_string();
            let key = if key.is_empty() || key == "." { "(top level)".to_string() } else { key };
            Err(Error::key(path, &key, e.into_inner().to_string()))
        }
        _ => Ok(()),
    }
}
