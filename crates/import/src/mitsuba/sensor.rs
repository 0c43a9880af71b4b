//! The sensor (camera and film) and the integrator's settings.

use super::*;

impl<'a> Importer<'a> {
    pub(super) fn sensor(&mut self, node: &'a Node) -> Result<(Camera, Film), LoadError> {
        let label = node.label();
        let ty = node.attr("type").unwrap_or("");
        if ty != "perspective" && ty != "thinlens" {
            return Err(self.err(
                node,
                format!("sensor type \"{ty}\" is not supported (perspective and thinlens are)"),
            ));
        }
        let film = match node.children.iter().find(|c| c.tag == "film") {
            Some(f) => {
                let w = self
                    .integer(f, "width")?
                    .unwrap_or(i64::from(DEFAULT_FILM.width));
                let h = self
                    .integer(f, "height")?
                    .unwrap_or(i64::from(DEFAULT_FILM.height));
                let side = |v: i64| {
                    u32::try_from(v)
                        .ok()
                        .filter(|&v| v > 0 && v <= super::super::MAX_FILM_SIDE)
                };
                let (Some(width), Some(height)) = (side(w), side(h)) else {
                    return Err(self.err(f, format!("film size {w}x{h} is out of range")));
                };
                if let Some(r) = f.children.iter().find(|c| c.tag == "rfilter")
                    && r.attr("type") != Some("box")
                {
                    self.builder.warn(format!(
                        "{}: fppm's pixels are box-filtered; the {} filter is not used",
                        r.label(),
                        r.attr("type").unwrap_or("")
                    ));
                }
                if prop(f, "crop_width").is_some() || prop(f, "crop_offset_x").is_some() {
                    self.builder
                        .warn(format!("{}: the crop window is ignored", f.label()));
                }
                Film { width, height }
            }
            None => DEFAULT_FILM,
        };
        let to_world = self.transform(node, "to_world")?;
        if to_world.determinant() < 0.0 {
            self.builder.warn(format!(
                "{label}: to_world mirrors the image; fppm renders it unmirrored"
            ));
        }
        let position = to_world.transform_point3(DVec3::ZERO);
        let forward = to_world
            .transform_vector3(DVec3::Z)
            .try_normalize()
            .ok_or_else(|| self.err(node, "to_world has no view direction"))?;
        let up = to_world
            .transform_vector3(DVec3::Y)
            .try_normalize()
            .ok_or_else(|| self.err(node, "to_world has no up direction"))?;
        let fov = self
            .float(node, "fov")?
            .ok_or_else(|| self.err(node, "needs a fov (focal_length is not supported)"))?;
        if !(fov > 0.0 && fov < 180.0) {
            return Err(self.err(node, format!("fov must be in (0, 180) degrees, got {fov}")));
        }
        let axis = self.string(node, "fov_axis")?.unwrap_or("x");
        let (w, h) = (f64::from(film.width), f64::from(film.height));
        let along = match axis {
            "x" => w,
            "y" => h,
            "diagonal" => w.hypot(h),
            "smaller" => w.min(h),
            "larger" => w.max(h),
            other => {
                return Err(self.err(
                    node,
                    format!("fov_axis \"{other}\" is not one of x, y, diagonal, smaller, larger"),
                ));
            }
        };
        let fov_y = 2.0 * ((fov.to_radians() * 0.5).tan() * h / along).atan();
        let (aperture, focus) = if ty == "thinlens" {
            let a = self.float(node, "aperture_radius")?.unwrap_or(0.0);
            let f = self.float(node, "focus_distance")?.unwrap_or(0.0);
            if !(a >= 0.0 && f > 0.0) {
                return Err(self.err(
                    node,
                    "a thinlens needs aperture_radius ≥ 0 and focus_distance > 0",
                ));
            }
            (a, f)
        } else {
            (
                0.0,
                self.float(node, "focus_distance")?
                    .filter(|f| *f > 0.0)
                    .unwrap_or(1.0),
            )
        };
        Ok((
            Camera {
                position: position.as_vec3(),
                look_at: (position + forward).as_vec3(),
                up: up.as_vec3(),
                fov_y: fov_y as f32,
                aperture_radius: aperture as f32,
                focus_distance: focus as f32,
            },
            film,
        ))
    }

    pub(super) fn integrator(
        &mut self,
        node: &'a Node,
        render: &mut RenderDefaults,
    ) -> Result<(), LoadError> {
        let label = node.label();
        let ty = node.attr("type").unwrap_or("");
        if !matches!(
            ty,
            "path" | "volpath" | "volpathmis" | "ptracer" | "prb" | "direct"
        ) {
            self.builder.warn(format!(
                "{label}: fppm renders global illumination with its own method instead"
            ));
        }
        if ty == "direct" {
            self.builder.warn(format!(
                "{label}: fppm renders all bounces, not direct light only"
            ));
        }
        if let Some(depth) = self.integer(node, "max_depth")? {
            match depth {
                -1 => {}
                d if d >= 2 => {
                    render.set("max_depth", u32::try_from(d - 1).unwrap_or(u32::MAX).min(1024));
                }
                d => self.builder.warn(format!(
                    "{label}: max_depth {d} (emitters seen directly only) cannot be rendered; fppm's default depth is used"
                )),
            }
        }
        // Mitsuba's `depth >= rr_depth` test runs at the rr_depth-th BSDF sample: fppm's
        // `rr_depth` counts bounces the same way.
        match self.integer(node, "rr_depth")? {
            Some(rr) if rr >= 1 => {
                render.set("rr_depth", u32::try_from(rr).unwrap_or(u32::MAX).min(1024));
            }
            Some(rr) => self.builder.warn(format!(
                "{label}: rr_depth {rr} is not a bounce; fppm's default is used"
            )),
            None => {}
        }
        if self.boolean(node, "hide_emitters")? == Some(true) {
            self.builder
                .warn(format!("{label}: hide_emitters is ignored"));
        }
        Ok(())
    }
}
