//! `<transform>`: its operations composed as Mitsuba composes them.

use super::*;

impl<'a> Importer<'a> {
    /// The `to_world` (or other named) transform of `node`, identity if absent.
    pub(super) fn transform(&self, node: &Node, name: &str) -> Result<DMat4, LoadError> {
        let Some(t) = prop(node, name) else {
            return Ok(DMat4::IDENTITY);
        };
        if t.tag != "transform" {
            return Err(self.err(
                t,
                format!("property \"{name}\" must be a <transform>, got <{}>", t.tag),
            ));
        }
        let mut m = DMat4::IDENTITY;
        for op in &t.children {
            let step = match op.tag.as_str() {
                "translate" => DMat4::from_translation(self.xyz(op, 0.0)?),
                "scale" => DMat4::from_scale(self.xyz(op, 1.0)?),
                "rotate" => {
                    let axis = self.xyz(op, 0.0)?;
                    let angle: f64 = op
                        .attr("angle")
                        .ok_or_else(|| self.err(op, "<rotate> needs an angle"))?
                        .trim()
                        .parse()
                        .map_err(|_| self.err(op, "angle is not a number"))?;
                    if axis == DVec3::ZERO {
                        return Err(self.err(op, "rotation axis cannot be zero"));
                    }
                    mitsuba_rotation(axis, angle.to_radians())
                }
                "lookat" => {
                    let parse = |k: &str| -> Result<Option<DVec3>, LoadError> {
                        op.attr(k)
                            .map(|v| {
                                let n = numbers(v).map_err(|m| self.err(op, m))?;
                                match n.as_slice() {
                                    [a, b, c] => Ok(DVec3::new(*a, *b, *c)),
                                    _ => Err(self.err(op, format!("{k} needs 3 values"))),
                                }
                            })
                            .transpose()
                    };
                    let origin =
                        parse("origin")?.ok_or_else(|| self.err(op, "<lookat> needs an origin"))?;
                    let target =
                        parse("target")?.ok_or_else(|| self.err(op, "<lookat> needs a target"))?;
                    let dir = (target - origin)
                        .try_normalize()
                        .ok_or_else(|| self.err(op, "origin and target coincide"))?;
                    let up = match parse("up")? {
                        Some(up) if up != DVec3::ZERO => up,
                        _ => dir.any_orthonormal_vector(),
                    };
                    let left = up
                        .cross(dir)
                        .try_normalize()
                        .ok_or_else(|| self.err(op, "up is parallel to the view direction"))?;
                    let new_up = dir.cross(left);
                    DMat4::from_cols(
                        left.extend(0.0),
                        new_up.extend(0.0),
                        dir.extend(0.0),
                        origin.extend(1.0),
                    )
                }
                "matrix" => {
                    let n = numbers(self.value(op)?).map_err(|m| self.err(op, m))?;
                    let size = match n.len() {
                        16 => 4,
                        9 => 3,
                        k => {
                            return Err(
                                self.err(op, format!("matrix needs 9 or 16 values, got {k}"))
                            );
                        }
                    };
                    let mut m = DMat4::IDENTITY;
                    for i in 0..size {
                        for j in 0..size {
                            // Row-major in the file; glam is column-major.
                            m.col_mut(j)[i] = n[i * size + j];
                        }
                    }
                    m
                }
                other => {
                    return Err(self.err(op, format!("unexpected <{other}> inside <transform>")));
                }
            };
            m = step * m;
        }
        if !m.is_finite() {
            return Err(self.err(t, "transform is not finite"));
        }
        Ok(m)
    }
}

/// Mitsuba's rotation (Dr.Jit's `rotate`): c·I + (1 − c)·a aᵀ + s·\[a\]×, with the axis `a`
/// used as written. Mitsuba does not normalise it, so neither does the importer: a scene with a
/// non-unit axis renders as in Mitsuba.
fn mitsuba_rotation(a: DVec3, theta: f64) -> DMat4 {
    let (s, c) = theta.sin_cos();
    let k = 1.0 - c;
    // Rows of the 3 × 3 part.
    let r0 = DVec3::new(
        c + a.x * a.x * k,
        a.x * a.y * k - a.z * s,
        a.x * a.z * k + a.y * s,
    );
    let r1 = DVec3::new(
        a.y * a.x * k + a.z * s,
        c + a.y * a.y * k,
        a.y * a.z * k - a.x * s,
    );
    let r2 = DVec3::new(
        a.z * a.x * k - a.y * s,
        a.z * a.y * k + a.x * s,
        c + a.z * a.z * k,
    );
    DMat4::from_cols(
        DVec3::new(r0.x, r1.x, r2.x).extend(0.0),
        DVec3::new(r0.y, r1.y, r2.y).extend(0.0),
        DVec3::new(r0.z, r1.z, r2.z).extend(0.0),
        glam::DVec4::W,
    )
}
