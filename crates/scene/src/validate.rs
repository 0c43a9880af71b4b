//! What makes a scene description valid, checked in one place: by every importer when it
//! finishes (which reports the [`Invalid`] as an error naming the file) and by `Scene::new` for
//! descriptions built in code (a [`SceneError`]). What follows from these
//! checks (finite positions, unit directions, non-negative colours, material indices in range)
//! is what the rest of the crate relies on: the BVH build cannot fail. That some emitter
//! carries power is the light sampler's check (`light/emitters.rs`, an [`Invalid`] too).

use std::f32::consts::PI;
use std::fmt;
use std::path::Path;

use glam::Vec3;

use crate::MaterialParam;
use crate::SceneError;
use crate::description::{Cylinder, Light, Material, SceneDescription};
use crate::{Environment, EnvironmentRadiance};

/// One problem of a scene description; the importers turn it into an error naming the file,
/// `Scene::new` into a [`SceneError`].
#[derive(Clone, Debug, PartialEq)]
#[non_exhaustive]
pub enum Invalid {
    /// A value outside its domain.
    Value {
        /// The value as the scene names it (`material "lamp" emission`).
        key: String,
        /// What is wrong (`must be finite, got [inf, 0, 0]`).
        message: String,
    },
    /// A primitive refers to a material that does not exist.
    MaterialIndex {
        /// The primitive, e.g. `triangle 12`.
        what: String,
        /// The material index it gives.
        index: u32,
        /// Number of materials.
        count: usize,
    },
    /// No light and no emitter has positive power (or every emitter has zero area).
    NoPower,
}

impl fmt::Display for Invalid {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Self::Value { key, message } => write!(f, "{key} {message}"),
            Self::MaterialIndex { what, index, count } => write!(
                f,
                "{what} refers to material {index} but there are {count} materials"
            ),
            Self::NoPower => write!(
                f,
                "no light: every light and emitter has zero power or zero area"
            ),
        }
    }
}

impl Invalid {
    fn value(key: impl Into<String>, message: impl Into<String>) -> Self {
        Self::Value {
            key: key.into(),
            message: message.into(),
        }
    }

    /// `Scene::new`'s error for this problem in the scene from `path`.
    pub(crate) fn in_scene(self, path: &Path) -> SceneError {
        let path = path.to_path_buf();
        match self {
            Self::Value { .. } => SceneError::Invalid {
                path,
                what: self.to_string(),
            },
            Self::MaterialIndex { what, index, count } => SceneError::MaterialIndex {
                path,
                what,
                index,
                count,
            },
            Self::NoPower => SceneError::NoLight { path },
        }
    }
}

/// Formats a vector as `[x, y, z]`.
pub fn fmt_vec(v: Vec3) -> String {
    format!("[{}, {}, {}]", v.x, v.y, v.z)
}

/// A colour (radiance, albedo, intensity): finite and non-negative.
pub fn colour(key: &str, c: Vec3) -> Result<(), Invalid> {
    if !c.is_finite() {
        return Err(Invalid::value(
            key,
            format!("must be finite, got {}", fmt_vec(c)),
        ));
    }
    if c.min_element() < 0.0 {
        return Err(Invalid::value(
            key,
            format!("must not be negative, got {}", fmt_vec(c)),
        ));
    }
    Ok(())
}

fn positive(key: String, x: f32) -> Result<(), Invalid> {
    if x.is_finite() && x > 0.0 {
        Ok(())
    } else {
        Err(Invalid::value(
            key,
            format!("must be finite and > 0, got {x}"),
        ))
    }
}

fn finite(key: String, v: Vec3) -> Result<(), Invalid> {
    if v.is_finite() {
        Ok(())
    } else {
        Err(Invalid::value(
            key,
            format!("must be finite, got {}", fmt_vec(v)),
        ))
    }
}

fn direction(key: String, v: Vec3) -> Result<(), Invalid> {
    if v.try_normalize().is_some() {
        Ok(())
    } else {
        Err(Invalid::value(
            key,
            format!("must be a finite non-zero vector, got {}", fmt_vec(v)),
        ))
    }
}

/// A material: colours finite and non-negative, index of refraction and roughness finite and
/// positive.
pub(crate) fn material(m: &Material) -> Result<(), Invalid> {
    let key = |what: &str| format!("material {:?} {what}", m.name);
    colour(&key("emission"), m.emission)?;
    for param in m.kind.params() {
        match param {
            MaterialParam::Colour(name, c) => colour(&key(name), c)?,
            MaterialParam::Positive(name, x) => positive(key(name), x)?,
        }
    }
    Ok(())
}

/// The colour that says how strong a light is (intensity or irradiance).
pub fn light_power(light: &Light) -> Vec3 {
    match *light {
        Light::Point { intensity, .. } | Light::Spot { intensity, .. } => intensity,
        Light::Directional { irradiance, .. } => irradiance,
    }
}

/// Light `i`: its power a colour, its position finite, its direction non-zero, a spot's cone
/// in (0, π] and its falloff start finite.
pub(crate) fn light(i: usize, light: &Light) -> Result<(), Invalid> {
    let key = |kind: &str, what: &str| format!("{kind} light {i} {what}");
    match *light {
        Light::Point {
            position,
            intensity,
        } => {
            colour(&key("point", "intensity"), intensity)?;
            finite(key("point", "position"), position)
        }
        Light::Spot {
            position,
            direction: axis,
            intensity,
            cone_angle,
            falloff_start,
        } => {
            colour(&key("spot", "intensity"), intensity)?;
            finite(key("spot", "position"), position)?;
            direction(key("spot", "direction"), axis)?;
            if !(cone_angle > 0.0 && cone_angle <= PI) {
                return Err(Invalid::value(
                    key("spot", "cone angle"),
                    format!("must be in (0, π] radians, got {cone_angle}"),
                ));
            }
            if falloff_start.is_finite() {
                Ok(())
            } else {
                Err(Invalid::value(
                    key("spot", "falloff start"),
                    format!("must be finite, got {falloff_start}"),
                ))
            }
        }
        Light::Directional {
            direction: axis,
            irradiance,
        } => {
            colour(&key("directional", "irradiance"), irradiance)?;
            direction(key("directional", "direction"), axis)
        }
    }
}

/// Cylinder `i`: finite, positive sizes, an arc in (0, 2π], perpendicular unit axis and facing,
/// and a material that does not emit (cylinders are not emitters).
fn cylinder(i: usize, c: &Cylinder, materials: &[Material]) -> Result<(), Invalid> {
    const TOLERANCE: f32 = 1e-4;
    let key = |what: &str| format!("cylinder {i} {what}");
    let Some(m) = materials.get(c.material as usize) else {
        return Err(Invalid::MaterialIndex {
            what: format!("cylinder {i}"),
            index: c.material,
            count: materials.len(),
        });
    };
    if !(c.center.is_finite() && c.axis.is_finite() && c.facing.is_finite()) {
        return Err(Invalid::value(
            key("center, axis and facing"),
            "must be finite",
        ));
    }
    positive(key("radius"), c.radius)?;
    positive(key("height"), c.height)?;
    if !(c.arc > 0.0 && c.arc <= std::f32::consts::TAU * (1.0 + TOLERANCE)) {
        return Err(Invalid::value(
            key("arc"),
            format!("must be in (0, 2π], got {}", c.arc),
        ));
    }
    if (c.axis.length() - 1.0).abs() > TOLERANCE
        || (c.facing.length() - 1.0).abs() > TOLERANCE
        || c.axis.dot(c.facing).abs() > TOLERANCE
    {
        return Err(Invalid::value(
            key("axis and facing"),
            "must be perpendicular unit vectors",
        ));
    }
    if m.emission.max_element() > 0.0 {
        return Err(Invalid::value(
            key("material"),
            format!("`{}` emits, but cylinders cannot", m.name),
        ));
    }
    Ok(())
}

/// Every check of a description: [`materials_and_lights`], then [`primitives`].
pub fn description(d: &SceneDescription) -> Result<(), Invalid> {
    materials_and_lights(&d.materials, &d.lights)?;
    if let Some(env) = &d.environment {
        environment(env)?;
    }
    primitives(d)?;
    media(d)
}

/// The environment light: a finite non-negative scale and rotation, a finite non-negative
/// constant radiance, or a map of the size its texels say (finite, non-negative texels are
/// checked when it is read, `EnvironmentMap::load`).
pub fn environment(env: &Environment) -> Result<(), Invalid> {
    if !(env.scale.is_finite() && env.scale >= 0.0) {
        return Err(Invalid::value(
            "environment scale",
            format!("must be finite and >= 0, got {}", env.scale),
        ));
    }
    let r = env.to_world;
    let orthonormal = (r.transpose() * r - glam::Mat3::IDENTITY)
        .to_cols_array()
        .iter()
        .all(|e| e.abs() < 1e-3);
    if !(r.is_finite() && orthonormal && (r.determinant() - 1.0).abs() < 1e-3) {
        return Err(Invalid::value(
            "environment to_world",
            format!("must be a rotation, got {r}"),
        ));
    }
    match &env.radiance {
        EnvironmentRadiance::Constant(c) => colour("environment radiance", *c),
        EnvironmentRadiance::Map(map) => {
            let (w, h) = (map.width as usize, map.height as usize);
            if w == 0 || w != 2 * h || map.texels.len() != w * h {
                return Err(Invalid::value(
                    format!("environment map `{}`", map.path.display()),
                    format!(
                        "must be 2:1 with one texel per pixel, got {w}×{h} and {} texels",
                        map.texels.len()
                    ),
                ));
            }
            match map
                .texels
                .iter()
                .position(|t| !t.is_finite() || t.cmplt(Vec3::ZERO).any())
            {
                Some(i) => Err(Invalid::value(
                    format!("environment map `{}`", map.path.display()),
                    format!(
                        "texel {i} is {} (must be finite and >= 0)",
                        fmt_vec(map.texels[i])
                    ),
                )),
                None => Ok(()),
            }
        }
    }
}

/// Every material and light.
pub fn materials_and_lights(materials: &[Material], lights: &[Light]) -> Result<(), Invalid> {
    for m in materials {
        material(m)?;
    }
    for (i, l) in lights.iter().enumerate() {
        light(i, l)?;
    }
    Ok(())
}

/// Each primitive's material index and geometry.
pub fn primitives(d: &SceneDescription) -> Result<(), Invalid> {
    let count = d.materials.len();
    let index = |what: String, index: u32| {
        if (index as usize) < count {
            Ok(())
        } else {
            Err(Invalid::MaterialIndex { what, index, count })
        }
    };
    for (i, t) in d.triangles.iter().enumerate() {
        index(format!("triangle {i}"), t.material)?;
        if !t.positions.iter().all(|p| p.is_finite())
            || !t.normals.is_none_or(|n| n.iter().all(|v| v.is_finite()))
            || !t
                .tangents
                .is_none_or(|n| n.iter().flatten().all(|v| v.is_finite()))
        {
            return Err(Invalid::value(
                format!("triangle {i}"),
                "has a non-finite vertex, normal or tangent",
            ));
        }
    }
    for (i, s) in d.spheres.iter().enumerate() {
        index(format!("sphere {i}"), s.material)?;
        finite(format!("sphere {i} center"), s.center)?;
        positive(format!("sphere {i} radius"), s.radius)?;
    }
    for (i, c) in d.cylinders.iter().enumerate() {
        cylinder(i, c, &d.materials)?;
    }
    Ok(())
}

/// The media and what refers to them: coefficients finite and non-negative, g in (−1, 1),
/// every medium, triangle and sphere index in range, every mesh that bounds a medium closed
/// (each edge shared by an even number of its triangles), and interface materials neither
/// emitting nor textured.
pub fn media(d: &SceneDescription) -> Result<(), Invalid> {
    for m in &d.materials {
        if matches!(m.kind, crate::MaterialKind::Interface(_))
            && (m.emission != Vec3::ZERO || m.textures.is_some())
        {
            return Err(Invalid::value(
                format!("material {:?}", m.name),
                "is an interface and cannot emit or have textures",
            ));
        }
    }
    let media = &d.media;
    for m in &media.list {
        let key = |what: &str| format!("medium {:?} {what}", m.name);
        colour(&key("sigma_a"), m.sigma_a)?;
        colour(&key("sigma_s"), m.sigma_s)?;
        if !(m.g > -1.0 && m.g < 1.0) {
            return Err(Invalid::value(
                key("g"),
                format!("must be in (-1, 1), got {}", m.g),
            ));
        }
        // A grid is valid by construction; its peak extinction must still be finite.
        if !m.is_homogeneous() && !m.majorant().is_finite() {
            return Err(Invalid::value(
                key("density"),
                "times its coefficients overflows (the peak extinction is not finite)",
            ));
        }
    }
    let count = media.list.len();
    let index = |key: String, m: Option<u32>| match m {
        Some(i) if i as usize >= count => Err(Invalid::value(
            key,
            format!("refers to medium {i} but there are {count} media"),
        )),
        _ => Ok(()),
    };
    index("camera medium".into(), media.camera)?;
    for (i, entry) in media.shapes.iter().enumerate() {
        let what = match entry.shape {
            crate::MediumShape::Triangles { start, end } => format!("triangles {start}..{end}"),
            crate::MediumShape::Sphere(s) => format!("sphere {s}"),
        };
        index(format!("{what} interior"), entry.interior)?;
        index(format!("{what} exterior"), entry.exterior)?;
        match entry.shape {
            crate::MediumShape::Triangles { start, end } => {
                if start >= end || end as usize > d.triangles.len() {
                    return Err(Invalid::value(
                        format!("media of shape {i}"),
                        format!("name {what} but there are {} triangles", d.triangles.len()),
                    ));
                }
                if entry.is_transition() {
                    closed(&what, &d.triangles[start as usize..end as usize])?;
                }
            }
            crate::MediumShape::Sphere(s) => {
                if s as usize >= d.spheres.len() {
                    return Err(Invalid::value(
                        format!("media of shape {i}"),
                        format!("name {what} but there are {} spheres", d.spheres.len()),
                    ));
                }
            }
        }
    }
    Ok(())
}

/// Whether the triangles close a volume: every edge (by the exact bits of its end points) is
/// shared by an even number of them. Meshes whose copies of a vertex differ in position by
/// rounding fail it; that is the documented limit (`docs/media.md`).
fn closed(what: &str, triangles: &[crate::Triangle]) -> Result<(), Invalid> {
    let key = |p: Vec3| p.to_array().map(|x| (x + 0.0).to_bits());
    let mut edges: std::collections::HashMap<([u32; 3], [u32; 3]), u32> =
        std::collections::HashMap::with_capacity(3 * triangles.len());
    for t in triangles {
        for k in 0..3 {
            let (a, b) = (key(t.positions[k]), key(t.positions[(k + 1) % 3]));
            *edges
                .entry(if a < b { (a, b) } else { (b, a) })
                .or_default() += 1;
        }
    }
    match edges.iter().filter(|(_, n)| *n % 2 == 1).min() {
        None => Ok(()),
        Some(((a, b), n)) => Err(Invalid::value(
            format!("the mesh of {what}"),
            format!(
                "bounds a medium but is not closed: its edge {} to {} belongs to {n} triangle(s)",
                fmt_vec(Vec3::from_array(a.map(f32::from_bits))),
                fmt_vec(Vec3::from_array(b.map(f32::from_bits)))
            ),
        )),
    }
}

#[cfg(test)]
#[path = "validate_media_tests.rs"]
mod media_tests;

#[cfg(test)]
mod tests {
    use super::*;
    use crate::test_util::{description, point_light, tri};

    #[track_caller]
    fn check(d: &SceneDescription, expect: &str) {
        let got = super::description(d).err().map(|e| e.to_string());
        assert_eq!(got.as_deref(), Some(expect));
        // Scene::new reports the same problem.
        let scene = crate::Scene::new(d.clone()).err().map(|e| e.to_string());
        assert!(scene.is_some_and(|e| e.ends_with(expect)), "{expect}");
    }

    #[test]
    fn one_check_for_every_path() {
        let floor = tri(Vec3::ZERO, Vec3::X, Vec3::Y, 0);
        let ok = description(vec![floor], Vec::new(), vec![point_light(Vec3::Z)]);
        assert_eq!(super::description(&ok), Ok(()));

        let mut d = ok.clone();
        d.lights = vec![Light::Spot {
            position: Vec3::Z,
            direction: -Vec3::Z,
            intensity: Vec3::ONE,
            cone_angle: 0.0,
            falloff_start: 0.0,
        }];
        check(
            &d,
            "spot light 0 cone angle must be in (0, π] radians, got 0",
        );
        d.lights = vec![Light::Directional {
            direction: Vec3::ZERO,
            irradiance: Vec3::ONE,
        }];
        check(
            &d,
            "directional light 0 direction must be a finite non-zero vector, got [0, 0, 0]",
        );

        let mut d = ok.clone();
        d.materials[0].emission = Vec3::new(-1.0, 0.0, 0.0);
        check(
            &d,
            "material \"m\" emission must not be negative, got [-1, 0, 0]",
        );

        let mut d = ok;
        d.triangles[0].material = 7;
        check(
            &d,
            "triangle 0 refers to material 7 but there are 2 materials",
        );
    }
}
