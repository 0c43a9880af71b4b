//! pbrt's shapes as fppm meshes.

use super::*;

impl Parser {
    pub(super) fn shape(
        &mut self,
        builder: &mut Builder,
        shape: &ShapeRecord,
        to_world: DMat4,
        material: u32,
        emissive: bool,
    ) -> Result<(), LoadError> {
        let p = &shape.params;
        let m = to_world.as_mat4();
        let loc = shape.loc;
        let label = format!("Shape \"{}\"", shape.kind);
        let mut mesh = match shape.kind.as_str() {
            "trianglemesh" | "loopsubdiv" | "bilinearmesh" => {
                let positions = self
                    .vec3s(p, "P", &["point3", "point"])?
                    .ok_or_else(|| self.err(loc, format!("{label} needs \"point3 P\"")))?;
                let normals = self.vec3s(p, "N", &["normal", "normal3"])?;
                let uvs = self.vec2s(p, "uv", &["point2", "float"])?;
                let indices = match self.ints(p, "indices")? {
                    Some(i) => i,
                    None if positions.len() == 3 && shape.kind == "trianglemesh" => vec![0, 1, 2],
                    None if positions.len() == 4 && shape.kind == "bilinearmesh" => {
                        vec![0, 1, 2, 3]
                    }
                    None => return Err(self.err(loc, format!("{label} needs \"integer indices\""))),
                };
                let per = if shape.kind == "bilinearmesh" { 4 } else { 3 };
                if indices.len() % per != 0 {
                    return Err(self.err(
                        loc,
                        format!(
                            "{label}: \"integer indices\" needs a multiple of {per} values, got {}",
                            indices.len()
                        ),
                    ));
                }
                let idx: Vec<u32> = indices
                    .iter()
                    .map(|&i| {
                        u32::try_from(i)
                            .map_err(|_| self.err(loc, format!("{label}: negative index {i}")))
                    })
                    .collect::<Result<_, _>>()?;
                let faces: Vec<[u32; 3]> = if per == 4 {
                    // pbrt's bilinear patch p00 p10 p01 p11, split along p00–p11.
                    idx.chunks(4)
                        .flat_map(|q| [[q[0], q[1], q[3]], [q[0], q[3], q[2]]])
                        .collect()
                } else {
                    idx.chunks(3).map(|t| [t[0], t[1], t[2]]).collect()
                };
                if shape.kind == "bilinearmesh" {
                    builder.warn(format!(
                        "{label}: each bilinear patch is split into two triangles"
                    ));
                }
                let mesh = IndexedMesh {
                    positions,
                    normals: normals.filter(|_| shape.kind == "trianglemesh"),
                    uvs: uvs.filter(|_| shape.kind != "loopsubdiv"),
                    indices: faces,
                };
                mesh.check_indices()
                    .map_err(|m| self.err(loc, format!("{label}: {m}")))?;
                if shape.kind == "loopsubdiv" {
                    let levels = self.int(p, "levels")?.unwrap_or(3);
                    let levels = u32::try_from(levels)
                        .ok()
                        .filter(|&l| {
                            l <= 12 && (mesh.indices.len() << (2 * l)) <= loop_subdiv::MAX_TRIANGLES
                        })
                        .ok_or_else(|| {
                            self.err(
                                loc,
                                format!("{label}: {levels} levels would make too many triangles"),
                            )
                        })?;
                    loop_subdiv::subdivide(&mesh.positions, &mesh.indices, levels)
                } else {
                    mesh
                }
            }
            "plymesh" => {
                let file = self
                    .str_param(p, "filename")?
                    .ok_or_else(|| self.err(loc, format!("{label} needs a \"string filename\"")))?;
                let path = self.resolve(&file);
                if p.get("displacement").is_some() {
                    builder.warn(format!("{label} ({file}): displacement is ignored"));
                }
                super::super::ply::load_ply(&path).map_err(|e| self.err(loc, e.to_string()))?
            }
            "sphere" => {
                let radius = self.float(p, "radius")?.unwrap_or(1.0) as f32;
                if p.get("zmin").is_some() || p.get("zmax").is_some() || p.get("phimax").is_some() {
                    builder.warn(format!(
                        "{label}: a partial sphere (zmin/zmax/phimax) is rendered whole"
                    ));
                }
                if !(radius.is_finite() && radius > 0.0) {
                    return Err(self.err(loc, format!("{label}: radius must be > 0, got {radius}")));
                }
                if shape.state.reverse {
                    builder.warn(format!(
                        "{label}: ReverseOrientation is ignored on a sphere"
                    ));
                }
                builder.sphere(Vec3::ZERO, radius, m, material, &label);
                return Ok(());
            }
            "disk" => {
                let radius = self.float(p, "radius")?.unwrap_or(1.0);
                let height = self.float(p, "height")?.unwrap_or(0.0);
                if self.float(p, "innerradius")?.unwrap_or(0.0) > 0.0 {
                    builder.warn(format!(
                        "{label}: the inner radius is ignored (a full disk)"
                    ));
                }
                builder.warn(format!(
                    "{label}: the disk is tessellated into {} triangles",
                    builder::DISK_SEGMENTS
                ));
                let mut mesh = IndexedMesh::disk();
                for v in &mut mesh.positions {
                    *v = Vec3::new(v.x * radius as f32, v.y * radius as f32, height as f32);
                }
                mesh
            }
            "cylinder" => {
                let radius = self.float(p, "radius")?.unwrap_or(1.0) as f32;
                let zmin = self.float(p, "zmin")?.unwrap_or(-1.0) as f32;
                let zmax = self.float(p, "zmax")?.unwrap_or(1.0) as f32;
                if !(radius > 0.0 && radius.is_finite() && zmax != zmin) {
                    return Err(
                        self.err(loc, format!("{label}: needs radius > 0 and zmin != zmax"))
                    );
                }
                if self.float(p, "phimax")?.is_some_and(|x| x < 360.0) {
                    builder.warn(format!("{label}: phimax is ignored (a whole cylinder)"));
                }
                builder::cylinder(
                    builder,
                    Vec3::new(0.0, 0.0, zmin),
                    Vec3::new(0.0, 0.0, zmax),
                    radius,
                    m,
                    material,
                    emissive,
                );
                return Ok(());
            }
            other => {
                return Err(self.err(loc, format!("Shape \"{other}\" is not supported")));
            }
        };
        if shape.state.reverse {
            mesh.flip();
        }
        let textured = builder
            .materials
            .get(material as usize)
            .is_some_and(|m| m.textures.is_some());
        if textured && mesh.uvs.is_none() {
            builder.warn(format!(
                "{label} at {}:{}: a textured material on a mesh without uv; fppm's default \
                 (the barycentrics) stands in for pbrt's",
                self.files[loc.file].display(),
                loc.line
            ));
        }
        // pbrt's image textures look up (s, 1 − t) with (0, 0) the image's top-left texel
        // (`SpectrumImageTexture::Evaluate`, src/pbrt/textures.cpp): v = 0 is the bottom row.
        mesh.flip_v();
        builder.mesh(&mesh, m, material);
        Ok(())
    }
}
