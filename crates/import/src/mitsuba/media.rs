//! Participating media: `<medium type="homogeneous">` (Mitsuba 3's `sigma_t`, `albedo`,
//! `scale`, or `sigma_a` and `sigma_s`) and `<medium type="heterogeneous">` (a `gridvolume`
//! `sigma_t` read from a `.vol` file, a constant `albedo`, `scale`), an `hg` or `isotropic`
//! phase function, referred to by shapes as `interior` and `exterior` and by the sensor as its
//! `medium` (`docs/media.md`).

use std::sync::Arc;

use super::*;

/// Mitsuba 3's default `albedo` of a homogeneous medium.
const DEFAULT_ALBEDO: f32 = 0.75;

impl<'a> Importer<'a> {
    /// The index of the medium `node` (an element or a `<ref>` to one), converted once.
    pub(super) fn medium(&mut self, node: &'a Node) -> Result<u32, LoadError> {
        let node = self.deref(node)?;
        let key = std::ptr::from_ref(node) as usize;
        if let Some(&i) = self.medium_cache.get(&key) {
            return Ok(i);
        }
        if node.tag != "medium" {
            return Err(self.err(node, "expected a <medium>"));
        }
        let ty = node.attr("type").unwrap_or("");
        let scale = self.float(node, "scale")?.unwrap_or(1.0) as f32;
        let (sigma_a, sigma_s, density) = match ty {
            "homogeneous" => {
                let (sigma_a, sigma_s) = match (prop(node, "sigma_a"), prop(node, "sigma_s")) {
                    (None, None) => {
                        let sigma_t = self
                            .colour(node, "sigma_t", SpectrumUse::Ior)?
                            .unwrap_or(Rgb::ONE);
                        let albedo = self
                            .colour(node, "albedo", SpectrumUse::Reflectance)?
                            .unwrap_or(Rgb::splat(DEFAULT_ALBEDO));
                        (sigma_t * (Rgb::ONE - albedo), sigma_t * albedo)
                    }
                    _ => (
                        self.colour(node, "sigma_a", SpectrumUse::Ior)?
                            .unwrap_or(Rgb::ZERO),
                        self.colour(node, "sigma_s", SpectrumUse::Ior)?
                            .unwrap_or(Rgb::ZERO),
                    ),
                };
                (sigma_a, sigma_s, None)
            }
            "heterogeneous" => self.heterogeneous(node)?,
            _ => {
                return Err(self.err(
                    node,
                    format!(
                        "medium type \"{ty}\" is not supported (only homogeneous and heterogeneous)"
                    ),
                ));
            }
        };
        let mut g = 0.0;
        for child in &node.children {
            let child = if child.tag == "ref" {
                self.deref(child)?
            } else {
                child
            };
            if child.tag != "phase" {
                continue;
            }
            match child.attr("type").unwrap_or("") {
                "isotropic" => g = 0.0,
                "hg" => g = self.float(child, "g")?.unwrap_or(0.8) as f32,
                other => {
                    return Err(self.err(
                        child,
                        format!(
                            "phase function \"{other}\" is not supported (only hg and isotropic)"
                        ),
                    ));
                }
            }
        }
        let name = node.attr("id").map_or_else(
            || format!("medium{}", self.builder.media.list.len()),
            str::to_owned,
        );
        let index = self.builder.media.list.len() as u32;
        self.builder.media.list.push(scene::Medium {
            name,
            sigma_a: sigma_a * scale,
            sigma_s: sigma_s * scale,
            g,
            density,
        });
        self.medium_cache.insert(key, index);
        Ok(index)
    }

    /// A `heterogeneous` medium's (σa, σs) at density 1, before `scale`, and its grid: Mitsuba 3's
    /// σt(x) = scale·sigma_t(x) and σs(x) = albedo·σt(x), with `sigma_t` a `gridvolume` (or a
    /// constant: then the medium is homogeneous) and `albedo` a constant (default 0.75).
    fn heterogeneous(
        &mut self,
        node: &'a Node,
    ) -> Result<(Rgb, Rgb, Option<Arc<scene::DensityGrid>>), LoadError> {
        let albedo_node = prop(node, "albedo").map(|n| self.deref(n)).transpose()?;
        if albedo_node.is_some_and(|n| n.tag == "volume") {
            return Err(self.err(
                node,
                "an albedo given as a volume is not supported (give a float or rgb)",
            ));
        }
        let albedo = self
            .colour(node, "albedo", SpectrumUse::Reflectance)?
            .unwrap_or(Rgb::splat(DEFAULT_ALBEDO));
        let sigma_t_node = prop(node, "sigma_t").map(|n| self.deref(n)).transpose()?;
        let (sigma_t, density) = match sigma_t_node {
            Some(volume) if volume.tag == "volume" => {
                (Rgb::ONE, Some(Arc::new(self.grid_volume(volume)?)))
            }
            _ => (
                self.colour(node, "sigma_t", SpectrumUse::Ior)?
                    .unwrap_or(Rgb::ONE),
                None,
            ),
        };
        Ok((sigma_t * (Rgb::ONE - albedo), sigma_t * albedo, density))
    }

    /// A `<volume type="gridvolume">` (or `grid`): its `.vol` file over the unit cube of its
    /// `to_world` (over the file's box with `use_grid_bbox`), trilinear and clamped at the
    /// faces, Mitsuba's defaults (other filters and wrap modes are refused).
    fn grid_volume(&mut self, volume: &'a Node) -> Result<scene::DensityGrid, LoadError> {
        let ty = volume.attr("type").unwrap_or("");
        if ty != "gridvolume" && ty != "grid" {
            return Err(self.err(
                volume,
                format!("volume type \"{ty}\" is not supported (only gridvolume)"),
            ));
        }
        if let Some(filter) = self.string(volume, "filter_type")?
            && filter != "trilinear"
        {
            return Err(self.err(
                volume,
                format!("filter_type \"{filter}\" is not supported (only trilinear)"),
            ));
        }
        if let Some(wrap) = self.string(volume, "wrap_mode")?
            && wrap != "clamp"
        {
            return Err(self.err(
                volume,
                format!("wrap_mode \"{wrap}\" is not supported (only clamp)"),
            ));
        }
        let file = self
            .string(volume, "filename")?
            .ok_or_else(|| self.err(volume, "needs a filename"))?;
        let path = self.doc.resolve(volume, file);
        // A bad grid file is a bad medium (exit 2), named with the XML line that refers to it.
        let vol = crate::vol::load_vol(&path)
            .map_err(|e| self.err(volume, e.to_string()).into_bad_medium())?;
        let (min, max) = if self.boolean(volume, "use_grid_bbox")?.unwrap_or(false) {
            (vol.min, vol.max)
        } else {
            (glam::Vec3::ZERO, glam::Vec3::ONE)
        };
        let to_world = glam::Affine3A::from_mat4(self.transform(volume, "to_world")?.as_mat4());
        scene::DensityGrid::new(
            vol.size,
            vol.data,
            scene::GridEdge::Clamp,
            min,
            max,
            to_world,
        )
        .map_err(|e| {
            self.err(volume, crate::vol::vol_error(&path, e).to_string())
                .into_bad_medium()
        })
    }

    /// The media a shape or sensor names: its `<medium name="…">` children and `<ref name="…">`
    /// to media, by name (`interior`, `exterior`, `medium`).
    pub(super) fn named_media(&mut self, node: &'a Node) -> Result<Vec<(&'a str, u32)>, LoadError> {
        let mut media = Vec::new();
        for child in &node.children {
            let is_medium = match child.tag.as_str() {
                "medium" => true,
                "ref" => self.deref(child)?.tag == "medium",
                _ => false,
            };
            if !is_medium {
                continue;
            }
            let name = child.attr("name").ok_or_else(|| {
                self.err(
                    child,
                    "a medium here needs a name (interior, exterior or medium)",
                )
            })?;
            media.push((name, self.medium(child)?));
        }
        Ok(media)
    }

    /// A shape's interior and exterior media.
    pub(super) fn shape_media(
        &mut self,
        node: &'a Node,
    ) -> Result<(Option<u32>, Option<u32>), LoadError> {
        let (mut interior, mut exterior) = (None, None);
        for (name, m) in self.named_media(node)? {
            match name {
                "interior" => interior = Some(m),
                "exterior" => exterior = Some(m),
                other => {
                    return Err(self.err(
                        node,
                        format!("a shape's medium is named interior or exterior, not \"{other}\""),
                    ));
                }
            }
        }
        Ok((interior, exterior))
    }

    /// The sensor's medium, if it names one.
    pub(super) fn sensor_medium(&mut self, node: &'a Node) -> Result<Option<u32>, LoadError> {
        let mut medium = None;
        for (name, m) in self.named_media(node)? {
            if name != "medium" {
                return Err(self.err(
                    node,
                    format!("a sensor's medium is named medium, not \"{name}\""),
                ));
            }
            medium = Some(m);
        }
        Ok(medium)
    }
}
