//! Participating media of a TOML scene (an extension, `docs/scene-format-extensions.md`):
//! `[media.NAME]` tables, and the names that shapes and the camera give as their media.

use std::collections::BTreeMap;
use std::sync::Arc;

use glam::{Affine3A, Vec3};
use scene::{DensityGrid, GridEdge, Medium};

use super::convert::Converter;
use super::schema::{GridToml, MediumToml};
use crate::error::LoadError;

/// The media by name, in name order, and each name's index.
pub(super) struct MediaNames {
    pub(super) list: Vec<Medium>,
    names: BTreeMap<String, u32>,
}

impl Converter<'_> {
    /// Every `[media.NAME]` table as a medium: coefficients finite and non-negative, `g` in
    /// (−1, 1), 0 by default, and an optional density grid (`[media.NAME.grid]`).
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
            let density = match m.grid {
                Some(grid) => Some(Arc::new(self.grid(&name, grid)?)),
                None => None,
            };
            media.names.insert(name.clone(), media.list.len() as u32);
            media.list.push(Medium {
                name,
                sigma_a,
                sigma_s,
                g,
                density,
            });
        }
        Ok(media)
    }

    /// The `[media.NAME.grid]` table: a `.vol` `file` (its box unless `min`/`max` are given)
    /// or inline `size` and `density` (box `min`/`max`, by default the unit cube), and the
    /// `edge` rule (`clamp`, the default, as Mitsuba; or `zero`, as pbrt).
    fn grid(&self, name: &str, grid: GridToml) -> Result<DensityGrid, LoadError> {
        let key = |k: &str| format!("[media.{name}.grid] {k}");
        let edge = match grid.edge.as_deref() {
            None | Some("clamp") => GridEdge::Clamp,
            Some("zero") => GridEdge::Zero,
            Some(other) => {
                return Err(self.invalid(
                    key("edge"),
                    format!("must be \"clamp\" or \"zero\", got {other:?}"),
                ));
            }
        };
        let (size, data, file_box, source) = match (grid.file, grid.size, grid.density) {
            (Some(file), None, None) => {
                let path = self.dir.join(file);
                let vol = crate::vol::load_vol(&path)?;
                (vol.size, vol.data, Some((vol.min, vol.max)), Some(path))
            }
            (None, Some(size), Some(density)) => (size, density, None, None),
            _ => {
                return Err(self.invalid(key("file"), "give either file, or size and density"));
            }
        };
        let (default_min, default_max) = file_box.unwrap_or((Vec3::ZERO, Vec3::ONE));
        let min = grid.min.map_or(default_min, Vec3::from);
        let max = grid.max.map_or(default_max, Vec3::from);
        DensityGrid::new(size, data, edge, min, max, Affine3A::IDENTITY).map_err(|e| match source {
            Some(path) => crate::vol::vol_error(&path, e),
            None => self.invalid(key("density"), e.to_string()),
        })
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
