//! The directive parser: files and includes, parameter lists, and the graphics state
//! each directive reads or changes.

use super::*;

impl Parser {
    pub(super) fn parse_file(&mut self, path: &Path, from: Option<Loc>) -> Result<(), LoadError> {
        let canonical = super::super::files::canonical(path);
        if let Some(loc) = from {
            if self.include_stack.contains(&canonical) {
                return Err(self.err(
                    loc,
                    format!("include cycle: {} includes itself", path.display()),
                ));
            }
            if self.include_stack.len() >= MAX_INCLUDE_DEPTH {
                return Err(self.err(
                    loc,
                    format!("includes nested deeper than {MAX_INCLUDE_DEPTH}"),
                ));
            }
            if !super::super::files::exists(path) {
                return Err(self.err(loc, format!("included file {} not found", path.display())));
            }
        }
        let text = super::super::read_text(path)?;
        let file = self.files.len();
        self.files.push(path.to_path_buf());
        let tokens = tokenize(&text, file, path)?;
        self.include_stack.push(canonical);
        let mut i = 0;
        while i < tokens.len() {
            let t = &tokens[i];
            let loc = loc_of(t);
            let Tok::Word(directive) = &t.tok else {
                return Err(self.err(
                    loc,
                    format!(
                        "syntax error: expected a directive, found {}",
                        describe(&t.tok)
                    ),
                ));
            };
            i += 1;
            self.directive(directive, loc, &tokens, &mut i)?;
        }
        self.include_stack.pop();
        Ok(())
    }

    /// Reads `n` numbers (bare, or in one bracketed list).
    pub(super) fn numbers(
        &self,
        tokens: &[Token],
        i: &mut usize,
        n: usize,
        loc: Loc,
        what: &str,
    ) -> Result<Vec<f64>, LoadError> {
        let bracket = matches!(tokens.get(*i).map(|t| &t.tok), Some(Tok::Open));
        if bracket {
            *i += 1;
        }
        let mut out = Vec::with_capacity(n);
        while out.len() < n {
            let Some(t) = tokens.get(*i) else {
                return Err(self.err(loc, format!("{what} needs {n} numbers, got {}", out.len())));
            };
            match &t.tok {
                Tok::Word(w) => {
                    let x: f64 = w.parse().map_err(|_| {
                        self.err(loc_of(t), format!("{what}: \"{w}\" is not a number"))
                    })?;
                    out.push(x);
                    *i += 1;
                }
                _ => {
                    return Err(
                        self.err(loc, format!("{what} needs {n} numbers, got {}", out.len()))
                    );
                }
            }
        }
        if bracket {
            match tokens.get(*i).map(|t| &t.tok) {
                Some(Tok::Close) => *i += 1,
                _ => {
                    return Err(self.err(
                        loc,
                        format!("{what} needs exactly {n} numbers in its brackets"),
                    ));
                }
            }
        }
        if out.iter().any(|x| !x.is_finite()) {
            return Err(self.err(loc, format!("{what}: numbers must be finite")));
        }
        Ok(out)
    }

    pub(super) fn string(
        &self,
        tokens: &[Token],
        i: &mut usize,
        loc: Loc,
        what: &str,
    ) -> Result<String, LoadError> {
        match tokens.get(*i).map(|t| &t.tok) {
            Some(Tok::Str(s)) => {
                *i += 1;
                Ok(s.clone())
            }
            _ => Err(self.err(loc, format!("syntax error: {what} needs a quoted string"))),
        }
    }

    /// Reads the parameter list that follows a directive.
    pub(super) fn params(&self, tokens: &[Token], i: &mut usize) -> Result<Params, LoadError> {
        let mut out = Vec::new();
        while let Some(t) = tokens.get(*i) {
            let Tok::Str(decl) = &t.tok else {
                break;
            };
            let loc = loc_of(t);
            let mut words = decl.split_whitespace();
            let (Some(ty), Some(name), None) = (words.next(), words.next(), words.next()) else {
                return Err(self.err(
                    loc,
                    format!(
                        "syntax error: \"{decl}\" is not a \"type name\" parameter declaration"
                    ),
                ));
            };
            *i += 1;
            let mut values = Vec::new();
            let single = !matches!(tokens.get(*i).map(|t| &t.tok), Some(Tok::Open));
            if !single {
                *i += 1;
            }
            loop {
                let Some(t) = tokens.get(*i) else {
                    if single {
                        return Err(self.err(loc, format!("parameter \"{decl}\" has no value")));
                    }
                    return Err(self.err(
                        loc,
                        format!("syntax error: parameter \"{decl}\" has no closing ]"),
                    ));
                };
                let v = match &t.tok {
                    Tok::Close if !single => {
                        *i += 1;
                        break;
                    }
                    Tok::Str(s) => Value::Str(s.clone()),
                    Tok::Word(w) if w == "true" || w == "false" => Value::Bool(w == "true"),
                    Tok::Word(w) => match w.parse::<f64>() {
                        Ok(x) => Value::Num(x),
                        Err(_) if single => {
                            return Err(self.err(loc, format!("parameter \"{decl}\" has no value")));
                        }
                        Err(_) => {
                            return Err(self.err(
                                loc,
                                format!("syntax error: parameter \"{decl}\" has no closing ] (found \"{w}\" on line {})", t.line),
                            ));
                        }
                    },
                    other => {
                        return Err(self.err(
                            loc_of(t),
                            format!("syntax error: unexpected {} in \"{decl}\"", describe(other)),
                        ));
                    }
                };
                values.push(v);
                *i += 1;
                if single {
                    break;
                }
            }
            out.push(Param {
                ty: ty.to_owned(),
                name: name.to_owned(),
                values,
                file: loc.file,
                line: loc.line,
                column: loc.column,
            });
        }
        Ok(Params(out))
    }

    /// Applies a transform to the CTM, honouring `ActiveTransform` (only the start time counts).
    pub(super) fn apply(&mut self, m: DMat4, replace: bool) {
        if self.active == Active::End {
            return;
        }
        self.state.ctm = if replace { m } else { self.state.ctm * m };
    }

    #[allow(clippy::too_many_lines)]
    pub(super) fn directive(
        &mut self,
        d: &str,
        loc: Loc,
        tokens: &[Token],
        i: &mut usize,
    ) -> Result<(), LoadError> {
        match d {
            "Include" | "Import" => {
                let name = self.string(tokens, i, loc, d)?;
                let path = self.resolve(&name);
                self.parse_file(&path, Some(loc))?;
            }
            "Identity" => self.apply(DMat4::IDENTITY, true),
            "Translate" => {
                let v = self.numbers(tokens, i, 3, loc, d)?;
                self.apply(DMat4::from_translation(DVec3::new(v[0], v[1], v[2])), false);
            }
            "Scale" => {
                let v = self.numbers(tokens, i, 3, loc, d)?;
                self.apply(DMat4::from_scale(DVec3::new(v[0], v[1], v[2])), false);
            }
            "Rotate" => {
                let v = self.numbers(tokens, i, 4, loc, d)?;
                let axis = DVec3::new(v[1], v[2], v[3])
                    .try_normalize()
                    .ok_or_else(|| self.err(loc, "Rotate: the axis cannot be zero"))?;
                self.apply(DMat4::from_axis_angle(axis, v[0].to_radians()), false);
            }
            "LookAt" => {
                let v = self.numbers(tokens, i, 9, loc, d)?;
                let pos = DVec3::new(v[0], v[1], v[2]);
                let look = DVec3::new(v[3], v[4], v[5]);
                let up = DVec3::new(v[6], v[7], v[8]);
                let dir = (look - pos).try_normalize().ok_or_else(|| {
                    self.err(loc, "LookAt: the eye and the point looked at coincide")
                })?;
                let right = up
                    .normalize_or_zero()
                    .cross(dir)
                    .try_normalize()
                    .ok_or_else(|| self.err(loc, "LookAt: up is parallel to the view direction"))?;
                let new_up = dir.cross(right);
                let world_from_camera = DMat4::from_cols(
                    right.extend(0.0),
                    new_up.extend(0.0),
                    dir.extend(0.0),
                    pos.extend(1.0),
                );
                self.apply(world_from_camera.inverse(), false);
            }
            "Transform" | "ConcatTransform" => {
                let v = self.numbers(tokens, i, 16, loc, d)?;
                // pbrt reads the 16 numbers column by column (its matrices are transposed on read).
                let m = DMat4::from_cols_array(
                    &v.try_into()
                        .map_err(|_| self.err(loc, "needs 16 numbers"))?,
                );
                self.apply(m, d == "Transform");
            }
            "CoordinateSystem" => {
                let name = self.string(tokens, i, loc, d)?;
                self.named_coords.insert(name, self.state.ctm);
            }
            "CoordSysTransform" => {
                let name = self.string(tokens, i, loc, d)?;
                let m = *self.named_coords.get(&name).ok_or_else(|| {
                    self.err(loc, format!("unknown coordinate system \"{name}\""))
                })?;
                self.apply(m, true);
            }
            "ReverseOrientation" => self.state.reverse = !self.state.reverse,
            "ActiveTransform" => {
                let which = match tokens.get(*i).map(|t| &t.tok) {
                    Some(Tok::Word(w)) => w.clone(),
                    _ => {
                        return Err(
                            self.err(loc, "ActiveTransform needs StartTime, EndTime or All")
                        );
                    }
                };
                *i += 1;
                self.active = match which.as_str() {
                    "StartTime" => Active::Start,
                    "EndTime" => Active::End,
                    "All" => Active::All,
                    other => {
                        return Err(self.err(
                            loc,
                            format!("ActiveTransform {other}: expected StartTime, EndTime or All"),
                        ));
                    }
                };
                self.warn("ActiveTransform: motion blur is not supported; the shutter-open (StartTime) transforms are used".to_owned());
            }
            "TransformTimes" => {
                self.numbers(tokens, i, 2, loc, d)?;
            }
            "AttributeBegin" | "TransformBegin" => {
                self.stack
                    .push((self.state.clone(), loc, d == "TransformBegin"));
            }
            "AttributeEnd" | "TransformEnd" => {
                let (saved, _, transform_only) = self
                    .stack
                    .pop()
                    .ok_or_else(|| self.err(loc, format!("{d} without a matching begin")))?;
                if transform_only {
                    self.state.ctm = saved.ctm;
                } else {
                    self.state = saved;
                }
            }
            "Attribute" => {
                self.string(tokens, i, loc, d)?;
                self.params(tokens, i)?;
                self.warn(
                    "Attribute: shape/light/material attribute defaults are ignored".to_owned(),
                );
            }
            "Option" | "ColorSpace" => {
                // Option "type name" value; ColorSpace "name".
                if d == "Option" {
                    self.params(tokens, i)?;
                } else {
                    self.string(tokens, i, loc, d)?;
                }
            }
            "Camera" => {
                let kind = self.string(tokens, i, loc, d)?;
                let p = self.params(tokens, i)?;
                if kind != "perspective" {
                    return Err(self.err(
                        loc,
                        format!("Camera \"{kind}\" is not supported (perspective is)"),
                    ));
                }
                let world_from_camera = self.state.ctm.inverse();
                if !world_from_camera.is_finite() {
                    return Err(self.err(loc, "Camera: the transform cannot be inverted"));
                }
                self.named_coords
                    .insert("camera".to_owned(), world_from_camera);
                let fov = self.float(&p, "fov")?.unwrap_or(90.0);
                if !(fov > 0.0 && fov < 180.0) {
                    return Err(self.err(
                        loc,
                        format!("Camera: fov must be in (0, 180) degrees, got {fov}"),
                    ));
                }
                let lens = self.float(&p, "lensradius")?.unwrap_or(0.0);
                let focal = self.float(&p, "focaldistance")?.unwrap_or(1e6);
                self.camera = Some((world_from_camera, fov, lens, focal));
                // pbrt-v4: the camera sits in the current outside medium.
                self.camera_medium = self
                    .state
                    .media
                    .as_ref()
                    .map(|m| (m.outside.clone(), m.loc));
            }
            "Film" => {
                let _kind = self.string(tokens, i, loc, d)?;
                let p = self.params(tokens, i)?;
                let w = self.int(&p, "xresolution")?.unwrap_or(1280);
                let h = self.int(&p, "yresolution")?.unwrap_or(720);
                let side = |v: i64| {
                    u32::try_from(v)
                        .ok()
                        .filter(|&v| v > 0 && v <= super::super::MAX_FILM_SIDE)
                };
                let (Some(width), Some(height)) = (side(w), side(h)) else {
                    return Err(self.err(loc, format!("Film: resolution {w}x{h} is out of range")));
                };
                self.film = Film { width, height };
                if p.get("cropwindow").is_some() {
                    self.warn("Film: the crop window is ignored".to_owned());
                }
            }
            "Integrator" => {
                let kind = self.string(tokens, i, loc, d)?;
                let p = self.params(tokens, i)?;
                if let Some(depth) = self.int(&p, "maxdepth")? {
                    let depth = u32::try_from(depth)
                        .ok()
                        .filter(|&d| d >= 1)
                        .ok_or_else(|| {
                            self.err(
                                loc,
                                format!("Integrator: maxdepth must be ≥ 1, got {depth}"),
                            )
                        })?;
                    self.render.set("max_depth", depth.min(1024));
                }
                if !matches!(
                    kind.as_str(),
                    "path" | "volpath" | "bdpt" | "mlt" | "sppm" | "lightpath" | "simplepath"
                ) {
                    self.warn(format!("Integrator \"{kind}\": fppm renders global illumination with its own method instead"));
                }
            }
            "Sampler" | "PixelFilter" | "Accelerator" => {
                self.string(tokens, i, loc, d)?;
                self.params(tokens, i)?;
            }
            "WorldBegin" => {
                self.state.ctm = DMat4::IDENTITY;
                self.named_coords
                    .insert("world".to_owned(), DMat4::IDENTITY);
            }
            "WorldEnd" => {}
            "MakeNamedMedium" => {
                let name = self.string(tokens, i, loc, d)?;
                let params = self.params(tokens, i)?;
                self.named_medium(name, &params, loc)?;
            }
            "MediumInterface" => {
                // MediumInterface "inside" "outside", or one name for both sides.
                let inside = self.string(tokens, i, loc, d)?;
                let outside = if matches!(tokens.get(*i).map(|t| &t.tok), Some(Tok::Str(_))) {
                    self.string(tokens, i, loc, d)?
                } else {
                    inside.clone()
                };
                self.state.media = Some(MediumNames {
                    inside,
                    outside,
                    loc,
                });
            }
            "Material" => {
                let kind = self.string(tokens, i, loc, d)?;
                let params = self.params(tokens, i)?;
                self.materials.push(MaterialDef { kind, params, loc });
                self.state.material = MaterialRef::Anonymous(self.materials.len() - 1);
            }
            "MakeNamedMaterial" => {
                let name = self.string(tokens, i, loc, d)?;
                let params = self.params(tokens, i)?;
                let kind = params
                    .get("type")
                    .and_then(|p| match p.values.as_slice() {
                        [Value::Str(s)] => Some(s.clone()),
                        _ => None,
                    })
                    .ok_or_else(|| {
                        self.err(
                            loc,
                            format!("MakeNamedMaterial \"{name}\" needs a \"string type\""),
                        )
                    })?;
                self.named_materials
                    .insert(name, MaterialDef { kind, params, loc });
            }
            "NamedMaterial" => {
                let name = self.string(tokens, i, loc, d)?;
                self.state.material = MaterialRef::Named(name, loc);
            }
            "Texture" => {
                let name = self.string(tokens, i, loc, d)?;
                let _ty = self.string(tokens, i, loc, d)?;
                let class = self.string(tokens, i, loc, d)?;
                let params = self.params(tokens, i)?;
                self.textures
                    .insert(name, TextureDef { class, params, loc });
            }
            "LightSource" => {
                let kind = self.string(tokens, i, loc, d)?;
                let params = self.params(tokens, i)?;
                self.lights.push(LightRecord {
                    kind,
                    params,
                    ctm: self.state.ctm,
                    loc,
                });
            }
            "AreaLightSource" => {
                let kind = self.string(tokens, i, loc, d)?;
                let params = self.params(tokens, i)?;
                if kind != "diffuse" {
                    return Err(self.err(
                        loc,
                        format!("AreaLightSource \"{kind}\" is not supported (diffuse is)"),
                    ));
                }
                self.state.area = Some(AreaLight { params, loc });
            }
            "Shape" => {
                let kind = self.string(tokens, i, loc, d)?;
                let params = self.params(tokens, i)?;
                let record = ShapeRecord {
                    kind,
                    params,
                    state: self.state.clone(),
                    loc,
                };
                match &mut self.current_object {
                    Some((_, shapes)) => shapes.push(record),
                    None => self.shapes.push(record),
                }
            }
            "ObjectBegin" => {
                let name = self.string(tokens, i, loc, d)?;
                if self.current_object.is_some() {
                    return Err(self.err(loc, "ObjectBegin inside another object"));
                }
                self.stack.push((self.state.clone(), loc, false));
                self.current_object = Some((name, Vec::new()));
            }
            "ObjectEnd" => {
                let (name, shapes) = self
                    .current_object
                    .take()
                    .ok_or_else(|| self.err(loc, "ObjectEnd without ObjectBegin"))?;
                self.objects.insert(name, shapes);
                if let Some((saved, _, _)) = self.stack.pop() {
                    self.state = saved;
                }
            }
            "ObjectInstance" => {
                let name = self.string(tokens, i, loc, d)?;
                let shapes = self
                    .objects
                    .get(&name)
                    .ok_or_else(|| {
                        self.err(loc, format!("ObjectInstance of unknown object \"{name}\""))
                    })?
                    .clone();
                let instance = self.state.ctm;
                for mut s in shapes {
                    s.state.ctm = instance * s.state.ctm;
                    self.shapes.push(s);
                }
            }
            other => {
                return Err(self.err(loc, format!("syntax error: unknown directive \"{other}\"")));
            }
        }
        Ok(())
    }
}
