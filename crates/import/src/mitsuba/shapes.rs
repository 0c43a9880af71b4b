//! Shapes: their meshes, BSDFs and area emitters.

use super::*;

impl<'a> Importer<'a> {
    /// The BSDF of a shape: a nested `<bsdf>`, or a `<ref>` to one. `None` if it has none.
    pub(super) fn shape_bsdf(&self, shape: &'a Node) -> Result<Option<&'a Node>, LoadError> {
        for child in &shape.children {
            let target = match child.tag.as_str() {
                "bsdf" => child,
                "ref" => {
                    let t = self.deref(child)?;
                    if t.tag != "bsdf" {
                        continue;
                    }
                    t
                }
                _ => continue,
            };
            return Ok(Some(target));
        }
        Ok(None)
    }

    /// The area emitter of a shape: a nested `<emitter>` or a `<ref>` to one.
    pub(super) fn shape_emitter(&self, shape: &'a Node) -> Result<Option<&'a Node>, LoadError> {
        for child in &shape.children {
            let target = match child.tag.as_str() {
                "emitter" => child,
                "ref" => {
                    let t = self.deref(child)?;
                    if t.tag != "emitter" {
                        continue;
                    }
                    t
                }
                _ => continue,
            };
            if target.attr("type") != Some("area") {
                return Err(self.err(target, "a shape can only carry an area emitter"));
            }
            return Ok(Some(target));
        }
        Ok(None)
    }

    /// A shape at the top level of the scene.
    pub(super) fn shape(&mut self, node: &'a Node, index: usize) -> Result<(), LoadError> {
        self.placed_shape(node, index, DMat4::IDENTITY, 0)
    }

    /// A shape whose `to_world` is applied after `parent` (an instance's, or the identity);
    /// `depth`: instances it is nested in.
    fn placed_shape(
        &mut self,
        node: &'a Node,
        index: usize,
        parent: DMat4,
        depth: usize,
    ) -> Result<(), LoadError> {
        let label = node.label();
        let ty = node.attr("type").unwrap_or("");
        match ty {
            // A declaration: its shapes appear where instances place them.
            "shapegroup" if depth == 0 => return Ok(()),
            "shapegroup" => return Err(self.err(node, "a shapegroup cannot be nested")),
            "instance" => return self.instance(node, index, parent, depth),
            _ => {}
        }
        let bsdf = match self.shape_bsdf(node)? {
            Some(b) => self.bsdf(b)?,
            None => ConvertedBsdf {
                name: "default".to_owned(),
                kind: Some(MaterialKind::Diffuse(scene::Diffuse {
                    albedo: Rgb::splat(DEFAULT_REFLECTANCE),
                })),
                textures: None,
                spectra: None,
            },
        };
        let (interior, exterior) = self.shape_media(node)?;
        let bounds_media = interior.is_some() || exterior.is_some();
        // A null BSDF is invisible, unless the shape bounds media: then it is their interface.
        let Some(kind) = bsdf
            .kind
            .or(bounds_media.then_some(MaterialKind::Interface(scene::Interface)))
        else {
            return Ok(());
        };
        let first_triangle = self.builder.triangles.len() as u32;
        let emitter = self.shape_emitter(node)?;
        let mut spectra = bsdf.spectra.as_deref().cloned().unwrap_or_default();
        let (name, emission) = match emitter {
            Some(e) => {
                let radiance = self
                    .colour(e, "radiance", SpectrumUse::Emission)?
                    .ok_or_else(|| self.err(e, "an area emitter needs a radiance"))?;
                spectra.emission = self.measured_spectrum(e, "radiance")?;
                let id = e
                    .attr("id")
                    .map_or_else(|| format!("shape{index}"), str::to_owned);
                (format!("{}+{id}", bsdf.name), radiance)
            }
            None => (bsdf.name.clone(), Rgb::ZERO),
        };
        let material = self.builder.material(Material {
            name,
            kind,
            emission,
            textures: bsdf.textures.clone(),
            spectra: (!spectra.is_empty()).then(|| std::sync::Arc::new(spectra)),
        });
        let to_world = parent * self.transform(node, "to_world")?;
        let m = to_world.as_mat4();
        let flip = self.boolean(node, "flip_normals")?.unwrap_or(false);
        let face_normals = self.boolean(node, "face_normals")?.unwrap_or(false);
        let mesh = match ty {
            "obj" | "ply" | "serialized" => {
                let file = self
                    .string(node, "filename")?
                    .ok_or_else(|| self.err(node, "needs a filename"))?;
                let path = self.doc.resolve(node, file);
                let wrap = |e: LoadError| self.err(node, e.to_string());
                let mut mesh = match ty {
                    "obj" => {
                        let data = super::super::obj::load_obj(&path).map_err(wrap)?;
                        let mut mesh = IndexedMesh::default();
                        let mut all_normals = true;
                        let mut all_uvs = true;
                        let mut normals = Vec::new();
                        let mut uvs = Vec::new();
                        for t in &data.triangles {
                            let base = mesh.positions.len() as u32;
                            mesh.positions.extend_from_slice(&t.positions);
                            match t.normals {
                                Some(n) => normals.extend_from_slice(&n),
                                None => all_normals = false,
                            }
                            match t.uv {
                                Some(uv) => uvs.extend_from_slice(&uv),
                                None => all_uvs = false,
                            }
                            mesh.indices.push([base, base + 1, base + 2]);
                        }
                        if all_normals && !data.triangles.is_empty() {
                            mesh.normals = Some(normals);
                        }
                        if all_uvs && !data.triangles.is_empty() {
                            // fppm's OBJ reader flips v as Mitsuba's does by default
                            // (`flip_tex_coords`, true for OBJ in src/shapes/obj.cpp).
                            mesh.uvs = Some(uvs);
                        }
                        mesh
                    }
                    "ply" => super::super::ply::load_ply(&path).map_err(wrap)?,
                    _ => {
                        let index = self.integer(node, "shape_index")?.unwrap_or(0);
                        let index = usize::try_from(index)
                            .map_err(|_| self.err(node, "shape_index must not be negative"))?;
                        super::super::serialized::load_serialized(&path, index).map_err(wrap)?
                    }
                };
                // Mitsuba's `flip_tex_coords` (v → 1 − v): true by default for OBJ, false for
                // PLY; `.serialized` meshes have no such option.
                let flip_default = ty == "obj";
                if ty != "serialized"
                    && self
                        .boolean(node, "flip_tex_coords")?
                        .unwrap_or(flip_default)
                        != flip_default
                {
                    mesh.flip_v();
                }
                if face_normals {
                    mesh.normals = None;
                } else if mesh.normals.is_none() && ty != "obj" {
                    mesh.compute_vertex_normals();
                }
                mesh
            }
            "rectangle" => IndexedMesh::rectangle(),
            "cube" => IndexedMesh::cube(),
            "disk" => {
                self.builder.warn(format!(
                    "{label}: the disk is tessellated into {} triangles",
                    builder::DISK_SEGMENTS
                ));
                IndexedMesh::disk()
            }
            "sphere" => {
                let center = self
                    .vector(node, "center")?
                    .unwrap_or(DVec3::ZERO)
                    .as_vec3();
                let radius = self.float(node, "radius")?.unwrap_or(1.0) as f32;
                if !(radius > 0.0 && radius.is_finite()) {
                    return Err(self.err(node, format!("radius must be > 0, got {radius}")));
                }
                if flip {
                    self.builder
                        .warn(format!("{label}: flip_normals is ignored on a sphere"));
                }
                if bounds_media {
                    self.builder.media.shapes.push(scene::ShapeMedia {
                        shape: scene::MediumShape::Sphere(self.builder.spheres.len() as u32),
                        interior,
                        exterior,
                    });
                }
                self.builder.sphere(center, radius, m, material, &label);
                return Ok(());
            }
            "cylinder" => {
                let p0 = self.vector(node, "p0")?.unwrap_or(DVec3::ZERO).as_vec3();
                let p1 = self.vector(node, "p1")?.unwrap_or(DVec3::Z).as_vec3();
                let radius = self.float(node, "radius")?.unwrap_or(1.0) as f32;
                if !(radius > 0.0 && radius.is_finite()) || (p1 - p0).length() <= 0.0 {
                    return Err(self.err(node, "a cylinder needs radius > 0 and p0 != p1"));
                }
                if bounds_media {
                    return Err(self.err(node, "a cylinder is open: it cannot bound a medium"));
                }
                if flip {
                    self.builder
                        .warn(format!("{label}: flip_normals is ignored on a cylinder"));
                }
                let emissive = emission_of(&self.builder, material);
                builder::cylinder(&mut self.builder, p0, p1, radius, m, material, emissive);
                return Ok(());
            }
            other => {
                return Err(self.err(node, format!("shape type \"{other}\" is not supported")));
            }
        };
        let mut mesh = mesh;
        if flip {
            mesh.flip();
        }
        self.builder.mesh(&mesh, m, material);
        let end = self.builder.triangles.len() as u32;
        if bounds_media && end > first_triangle {
            self.builder.media.shapes.push(scene::ShapeMedia {
                shape: scene::MediumShape::Triangles {
                    start: first_triangle,
                    end,
                },
                interior,
                exterior,
            });
        }
        Ok(())
    }
}

impl<'a> Importer<'a> {
    /// `<shape type="instance">`: the shapes of the `<shapegroup>` it refers to, each placed by
    /// its own `to_world` and then the instance's (Mitsuba's order), flattened into triangles.
    fn instance(
        &mut self,
        node: &'a Node,
        index: usize,
        parent: DMat4,
        depth: usize,
    ) -> Result<(), LoadError> {
        /// Deeper nesting than any real scene, so that a group that instances itself (through
        /// refs) ends with an error instead of a stack overflow.
        const MAX_DEPTH: usize = 16;
        if depth >= MAX_DEPTH {
            return Err(self.err(
                node,
                "instances nest too deeply (does a group instance itself?)",
            ));
        }
        let refs: Vec<&Node> = node.children.iter().filter(|c| c.tag == "ref").collect();
        let [reference] = refs.as_slice() else {
            return Err(self.err(node, "an instance needs exactly one <ref> to a shapegroup"));
        };
        let group = self.deref(reference)?;
        if group.tag != "shape" || group.attr("type") != Some("shapegroup") {
            return Err(self.err(reference, "an instance must refer to a shapegroup"));
        }
        let to_world = parent * self.transform(node, "to_world")?;
        for child in &group.children {
            match child.tag.as_str() {
                "shape" if child.attr("type") == Some("shapegroup") => {
                    return Err(self.err(child, "a shapegroup cannot be nested"));
                }
                "shape" => self.placed_shape(child, index, to_world, depth + 1)?,
                _ => {}
            }
        }
        Ok(())
    }
}

/// Whether material `index` emits.
fn emission_of(builder: &Builder, index: u32) -> bool {
    builder
        .materials
        .get(index as usize)
        .is_some_and(|m| m.emission.max_element() > 0.0)
}
