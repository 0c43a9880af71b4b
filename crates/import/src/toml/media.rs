//! Participating media of a TOML scene (an extension, `docs/scene-format-extensions.md`):
//! `[media.NAME]` tables, and the names that shapes and the camera give as their media.

use std::collections::BTreeMap;

use scene::Medium;

use super::convert::Converter;
use super::schema::MediumToml;
use crate::error::LoadError;

/// The media by name, in name order, and each name's index.
pub(super) struct MediaNames {
    pub(super) list: Vec<Medium>,
    names: BTreeMap<String, u32>,
}

impl Converter<'_> {
    /// Every `[media.NAME]` table as a medium: coefficients finite and non-negative, `g` in
    /// (−1, 1), 0 by default.
    pub(super) fn media(
        &self,
        tables: BTreeMap<String, MediumToml>,
    ) -> Result<MediaNames, LoadError> {
        let mut media = MediaNames {
            list: Vec::with_capacity(tables.len()),
            names: BTreeMap::new(),
        };
        for (name, m) in tables {
            let key = |k: &str| format!("[media.{name}] {k}");
            let sigma_a = self.colour(&key("sigma_a"), m.sigma_a)?;
            let sigma_s = self.colour(&key("sigma_s"), m.sigma_s)?;
            let g = m.g.unwrap_or(0.0);
            if !(g > -1.0 && g < 1.0) {
                return Err(self.invalid(key("g"), format!("must be in (-1, 1), got {g}")));
            }
            media.names.insert(name.clone(), media.list.len() as u32);
            media.list.push(Medium {
                name,
                sigma_a,
                sigma_s,
                g,
            });
        }
        Ok(media)
    }

    /// The index of the medium `name` that `key` gives; `None` for no name (vacuum).
    pub(super) fn medium_ref(
        &self,
        media: &MediaNames,
        key: &str,
        name: Option<&str>,
    ) -> Result<Option<u32>, LoadError> {
        let Some(name) = name else {
            return Ok(None);
        };
        match media.names.get(name) {
            Some(&i) => Ok(Some(i)),
            None => {
                let defined = if media.names.is_empty() {
                    "none".to_owned()
                } else {
                    media.names.keys().cloned().collect::<Vec<_>>().join(", ")
                };
                Err(self.invalid(
                    key,
                    format!("names medium `{name}`, which is not defined (media: {defined})"),
                ))
            }
        }
    }
}
