//! Scattering models (BSDFs), one module per model, each with its evaluation, sampling,
//! density, albedo and frequency lobe together:
//! - `diffuse.rs`: Lambert;
//! - `mirror.rs`: a perfect specular conductor of constant reflectance;
//! - `dielectric.rs`: a smooth dielectric with exact unpolarised Fresnel;
//! - `glossy.rs`: a GGX conductor over an optional Lambertian base;
//! - `conductor.rs`: a smooth or GGX conductor with exact Fresnel for a complex index of
//!   refraction;
//! - `rough_dielectric.rs`: GGX microfacet reflection and refraction with exact Fresnel;
//! - `interface.rs`: no scattering at all, a boundary of participating media.
//!
//! [`MaterialKind`] is a material's model as a scene describes it, and [`Bsdf`] a model at one
//! surface point. A new model is a module here implementing [`Model`], a variant of
//! [`MaterialKind`] with its line in `with_model!`, and the importers' lines that read it:
//! checks ([`crate::validate`]), summaries and fingerprints read its [`Model::params`].
//!
//! Conventions (pbrt's): `outgoing` and `incoming` are world-space unit vectors pointing away from
//! the surface; `outgoing` points back along the path being traced (toward the camera for camera
//! paths, toward the light for photon paths). [`Bsdf::eval`] returns f without the cosine.
//! All materials scatter on both sides: a reflection needs `outgoing` and `incoming` on the same
//! side of the shading normal, whichever side that is. [`Bsdf::pdfs`] and
//! [`Bsdf::sample_with_pdfs`] give the densities of an event in both directions ([`BsdfPdfs`]),
//! for bidirectional methods.
//!
//! [`Bsdf::eval`] is the BSDF that radiance sees ([`TransportMode::Radiance`]) with `outgoing`
//! toward the camera end of the path, which is how every caller evaluates it (next-event
//! estimation, a hitpoint's photon gather, a light vertex's connection to the lens); it differs
//! from the light paths' adjoint only across a refraction of finite density (the rough
//! dielectric), by the factor η′² that [`TransportMode`] describes.

mod conductor;
#[cfg(test)]
mod conductor_tests;
mod dielectric;
mod diffuse;
mod glossy;
mod interface;
mod mirror;
#[cfg(test)]
pub(crate) mod pdf_tests;
mod rough_dielectric;
#[cfg(test)]
mod rough_dielectric_tests;
#[cfg(test)]
mod tests;

use glam::{Vec2, Vec3};

pub use self::conductor::Conductor;
pub use self::dielectric::{Dielectric, fresnel_dielectric};
pub use self::diffuse::Diffuse;
pub use self::glossy::Glossy;
pub use self::interface::Interface;
pub use self::mirror::Mirror;
pub use self::rough_dielectric::{RoughDielectric, SMOOTH_ROUGHNESS};
use crate::{Frame, Hit, Material, Rgb};

/// What a path carries, which matters for refraction (Veach 1997, §5.2; pbrt's `TransportMode`).
///
/// Camera paths carry [`TransportMode::Radiance`]: refraction scales it by 1/η′² (η′ = η of the side
/// `incoming` points into over η of the side of `outgoing`). Photon (light) paths carry
/// [`TransportMode::Importance`]-like flux, which refraction does not scale.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum TransportMode {
    /// Camera paths: radiance.
    Radiance,
    /// Light (photon) paths: flux / importance.
    Importance,
}

/// The angular width of a material's scattering lobe, for the frequency operators (frequency-algebra §7).
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Lobe {
    /// A delta lobe (mirror, smooth dielectric): σρ = 0.
    Specular,
    /// A Lambertian lobe: infinitely wide.
    Lambert,
    /// A GGX lobe of roughness α (not squared): σρ² ≈ α².
    Ggx {
        /// GGX α.
        alpha: f32,
    },
}

/// A direction drawn by [`Bsdf::sample`].
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct BsdfSample {
    /// Unit world-space direction away from the surface.
    pub incoming: Vec3,
    /// f·|cos θᵢ|/pdf per channel: the factor the path throughput is multiplied by.
    pub weight: Rgb,
    /// Solid-angle density of `incoming`; for specular samples the discrete probability of the chosen lobe.
    pub pdf: f32,
    /// Whether `incoming` came from a delta lobe (no [`Bsdf::eval`]/[`Bsdf::pdf`] counterpart).
    pub is_specular: bool,
    /// Whether `incoming` is on the other side of the surface than `outgoing`.
    pub is_transmission: bool,
}

/// The densities of one scattering event traced both ways, for the multiple importance sampling
/// weights of bidirectional methods (Veach 1997, §10.2; the forward and reverse densities of
/// Georgiev's "Implementing Vertex Connection and Merging", 2012, and of pbrt-v4's BDPT).
///
/// For a surface point with `outgoing` and `incoming`, `forward` is the density with which
/// [`Bsdf::sample`] from `outgoing` draws `incoming`, and `reverse` the density with which it
/// draws `outgoing` from `incoming`: the same event as the path from the other end samples it.
/// - Lobes of finite density (diffuse, glossy): both are solid-angle densities (sr⁻¹), and
///   `reverse` is `forward` with the two directions swapped ([`Bsdf::pdf`] of each order).
/// - Delta lobes (`is_specular`: a mirror, a smooth dielectric): both are the discrete probability
///   of choosing the lobe, from the side each direction arrives on, and the Dirac factor that
///   both directions share is left out, as in [`BsdfSample::pdf`], SmallVCM and pbrt: one for a
///   mirror; for a dielectric Fresnel's R seen from that side for reflection and 1 − R for
///   refraction (equal both ways, by the reciprocity of Fresnel's equations).
///
/// No density depends on the [`TransportMode`]: the models choose their lobes by Fresnel and
/// albedo, never by the mode's scaled weight, so camera and light paths sample alike.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct BsdfPdfs {
    /// Density of drawing `incoming` from `outgoing`.
    pub forward: f32,
    /// Density of drawing `outgoing` from `incoming`.
    pub reverse: f32,
    /// Whether the event is a delta lobe's: the densities are then discrete probabilities.
    pub is_specular: bool,
}

/// The scattering models of scene format version 1 (and its extensions): each variant holds
/// the parameters of one model.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum MaterialKind {
    /// Lambertian reflector.
    Diffuse(Diffuse),
    /// Perfect specular reflection.
    Mirror(Mirror),
    /// Smooth dielectric with exact unpolarised Fresnel.
    Dielectric(Dielectric),
    /// Rough conductor with a GGX (Trowbridge–Reitz) distribution and Smith shadowing,
    /// optionally over a Lambertian base.
    Glossy(Glossy),
    /// Rough dielectric: GGX microfacet reflection and refraction with exact unpolarised
    /// Fresnel (the smooth dielectric below [`SMOOTH_ROUGHNESS`]).
    RoughDielectric(RoughDielectric),
    /// No scattering: a boundary of participating media that light crosses unchanged (an
    /// extension, `docs/media.md`). Only integrators that handle media render it.
    Interface(Interface),
    /// A conductor with exact Fresnel for its complex index of refraction, smooth or GGX.
    Conductor(Conductor),
}

/// Evaluates `$body` with `$model` bound to the model inside `$kind`, whichever it is: the one
/// place that lists every model.
macro_rules! with_model {
    ($kind:expr, $model:ident => $body:expr) => {
        match $kind {
            MaterialKind::Diffuse($model) => $body,
            MaterialKind::Mirror($model) => $body,
            MaterialKind::Dielectric($model) => $body,
            MaterialKind::Glossy($model) => $body,
            MaterialKind::RoughDielectric($model) => $body,
            MaterialKind::Interface($model) => $body,
            MaterialKind::Conductor($model) => $body,
        }
    };
}

/// One named parameter of a model, as the description checks, summaries and fingerprints read
/// it.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum MaterialParam {
    /// A colour, each channel finite and ≥ 0 (an albedo or reflectance also ≤ 1 in practice).
    Colour(&'static str, Rgb),
    /// A finite positive number.
    Positive(&'static str, f32),
}

/// What a model needs of the surface point besides its own parameters.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct Shading {
    /// The unit shading normal. The shading frame is built from it where a model needs one
    /// (`Frame::from_normal` is a pure function of it): a photon killed by the roulette, or a
    /// Lambertian evaluated against a normal, never needs the tangents.
    pub(crate) normal: Vec3,
    /// η on the far side of the shading normal over η on its side ([`Model::eta`]).
    pub(crate) eta: f32,
    /// A texture's colour that the model keeps apart from its parameters ([`Model::tint`]).
    pub(crate) tint: Rgb,
}

/// The interface of a scattering model. Local directions are in the shading frame (z along the
/// shading normal).
pub(crate) trait Model: Copy {
    /// Its name in scene files and summaries.
    const NAME: &'static str;
    /// Whether a lobe of finite density transmits: [`Bsdf`] then evaluates it through
    /// [`Model::eval_through`] and [`Model::pdf_through`], which see both local directions as
    /// they are (either side), instead of [`Model::eval_local`] and [`Model::pdf_local`], which
    /// see a same-side pair mirrored into the upper hemisphere.
    const TRANSMITS: bool = false;
    /// The lobe for the frequency operators.
    fn lobe(&self) -> Lobe;
    /// The reflectance it shows at normal incidence (the albedo AOV).
    fn albedo(&self) -> Rgb;
    /// Its parameters, in the order the description checks report them.
    fn params(&self) -> Vec<MaterialParam>;
    /// Folds a texture's colour into the model where the colour is one of its parameters, and
    /// returns the factor it keeps apart instead (one where it folded or ignores it).
    fn tint(&mut self, tint: Rgb) -> Rgb;
    /// Its albedo if it is Lambertian: the photon loop then decides the roulette and evaluates
    /// gathered photons without the shading frame.
    #[inline]
    fn lambertian_albedo(&self) -> Option<Rgb> {
        None
    }
    /// η on the far side of the shading normal over η on its side, where the normal faces the
    /// outside if `front_face`; one for models that do not refract.
    #[inline]
    fn eta(&self, _front_face: bool) -> f32 {
        1.0
    }
    /// The index of refraction relative to the outside, for models that refract.
    #[inline]
    fn refractive_index(&self) -> Option<f32> {
        None
    }
    /// f(outgoing, incoming) computed without the shading frame, where the model can.
    fn eval_world(&self, _s: &Shading, _outgoing: Vec3, _incoming: Vec3) -> Option<Rgb> {
        None
    }
    /// f for local directions on the same side, both mirrored into the upper hemisphere. The
    /// default is the delta lobes' zero: a model with a lobe of finite density overrides it.
    #[inline]
    fn eval_local(&self, _s: &Shading, _wo: Vec3, _wi: Vec3) -> Rgb {
        debug_assert!(
            self.lobe() == Lobe::Specular,
            "{} needs eval_local",
            Self::NAME
        );
        Rgb::ZERO
    }
    /// The solid-angle density of [`Model::sample_local`] for local directions on the same
    /// side, both in the upper hemisphere. The default is the delta lobes' zero, as for
    /// [`Model::eval_local`].
    #[inline]
    fn pdf_local(&self, _wo: Vec3, _wi: Vec3) -> f32 {
        debug_assert!(
            self.lobe() == Lobe::Specular,
            "{} needs pdf_local",
            Self::NAME
        );
        0.0
    }
    /// f (for radiance) of a model that [`Model::TRANSMITS`], for local directions on either
    /// side, the same or opposite ones.
    #[inline]
    fn eval_through(&self, _s: &Shading, _wo: Vec3, _wi: Vec3) -> Rgb {
        Rgb::ZERO
    }
    /// The solid-angle density of [`Model::sample_local`] for a model that
    /// [`Model::TRANSMITS`], for local directions on either side.
    #[inline]
    fn pdf_through(&self, _s: &Shading, _wo: Vec3, _wi: Vec3) -> f32 {
        0.0
    }
    /// The probability that [`Model::sample_local`] from the local `wo` (either side, finite,
    /// z ≠ 0) picks its delta refraction if `transmission`, else its delta reflection: the `pdf`
    /// of such a sample. The default is zero, for a model without delta lobes.
    #[inline]
    fn delta_probability(&self, _s: &Shading, _wo: Vec3, _transmission: bool) -> f32 {
        0.0
    }
    /// Draws `incoming` for the local `wo` (either side, finite, z ≠ 0).
    fn sample_local(
        &self,
        s: &Shading,
        frame: &Frame,
        wo: Vec3,
        u_lobe: f32,
        u: Vec2,
        mode: TransportMode,
    ) -> Option<BsdfSample>;
}

/// [`Model::NAME`] of the model behind a reference, for [`with_model!`].
#[inline]
fn model_name<M: Model>(_: &M) -> &'static str {
    M::NAME
}

/// [`Model::TRANSMITS`] of the model behind a reference, for [`with_model!`].
#[inline]
fn transmits<M: Model>(_: &M) -> bool {
    M::TRANSMITS
}

impl MaterialKind {
    /// A dielectric of index `ior` with GGX roughness `roughness` as the importers read it: the
    /// smooth [`Dielectric`] below [`SMOOTH_ROUGHNESS`] (which it renders as anyway), else a
    /// [`RoughDielectric`]. Neither value is checked here (validation does).
    #[must_use]
    pub fn dielectric(ior: f32, roughness: f32) -> Self {
        if roughness < SMOOTH_ROUGHNESS {
            Self::Dielectric(Dielectric { ior })
        } else {
            Self::RoughDielectric(RoughDielectric { ior, roughness })
        }
    }

    /// The model's name in scene files and summaries: `diffuse`, `mirror`, `dielectric`,
    /// `glossy`, `roughdielectric`, `interface`, `conductor`.
    #[must_use]
    #[inline]
    pub fn name(&self) -> &'static str {
        with_model!(self, m => model_name(m))
    }

    /// The lobe for the frequency operators. A glossy material with a diffuse base reports its
    /// GGX lobe.
    #[must_use]
    #[inline]
    pub fn lobe(&self) -> Lobe {
        with_model!(self, m => m.lobe())
    }

    /// Whether every lobe is a delta (mirror, smooth dielectric).
    #[must_use]
    #[inline]
    pub fn is_specular(&self) -> bool {
        self.lobe() == Lobe::Specular
    }

    /// The reflectance the material shows at normal incidence (the albedo AOV): a diffuse
    /// albedo, a mirror's reflectance, one for a dielectric, specular plus diffuse for a glossy
    /// material.
    #[must_use]
    #[inline]
    pub fn albedo(&self) -> Rgb {
        with_model!(self, m => m.albedo())
    }

    /// The model's parameters, by name.
    #[must_use]
    pub fn params(&self) -> Vec<MaterialParam> {
        with_model!(self, m => m.params())
    }

    /// The albedo of a Lambertian model, `None` for every other model.
    #[inline]
    #[must_use]
    pub fn lambertian_albedo(&self) -> Option<Rgb> {
        with_model!(self, m => m.lambertian_albedo())
    }

    /// The index of refraction relative to the outside, for a model that refracts.
    #[must_use]
    #[inline]
    pub fn refractive_index(&self) -> Option<f32> {
        with_model!(self, m => m.refractive_index())
    }

    /// Whether a lobe of finite density transmits (a rough dielectric that is not rendered
    /// smooth): light arriving on either side of the surface leaves toward a viewer, so a
    /// hitpoint there gathers photons from both sides.
    #[must_use]
    #[inline]
    pub fn transmits(&self) -> bool {
        with_model!(self, m => transmits(m)) && !self.is_specular()
    }
}

/// A material's scattering at one surface point, in the hit's shading frame.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Bsdf {
    kind: MaterialKind,
    shading: Shading,
}

impl Bsdf {
    /// The BSDF of `material` at `hit`, in the frame of its shading normal. A dielectric's inside is
    /// behind the front face: a hit on the front face enters the medium.
    #[inline]
    pub fn new(material: &Material, hit: &Hit) -> Self {
        Self::from_normal(material.kind, hit.shading_normal, hit.front_face)
    }

    /// The BSDF of `kind` around the unit `normal`; `front_face` tells whether `normal` points to the
    /// outside of a dielectric.
    #[inline]
    pub fn from_normal(kind: MaterialKind, normal: Vec3, front_face: bool) -> Self {
        Self {
            kind,
            shading: Shading {
                normal,
                eta: with_model!(kind, m => m.eta(front_face)),
                tint: Rgb::ONE,
            },
        }
    }

    /// [`Bsdf::from_normal`] with a texture colour `tint` that multiplies the BSDF: folded into a
    /// diffuse albedo or a mirror reflectance, kept as a factor of the whole glossy BSDF, ignored
    /// by a dielectric.
    #[inline]
    pub fn tinted(kind: MaterialKind, normal: Vec3, front_face: bool, tint: Rgb) -> Self {
        let mut bsdf = Self::from_normal(kind, normal, front_face);
        bsdf.shading.tint = with_model!(&mut bsdf.kind, m => m.tint(tint));
        bsdf
    }

    /// The scattering model, with a texture's colour folded into a diffuse albedo or a mirror
    /// reflectance (a glossy BSDF's texture colour is a separate factor).
    pub fn kind(&self) -> MaterialKind {
        self.kind
    }

    /// The shading frame (its `n` is the shading normal).
    #[inline]
    pub fn frame(&self) -> Frame {
        Frame::from_normal(self.shading.normal)
    }

    /// Whether the BSDF is purely specular (mirror, smooth dielectric): [`Bsdf::eval`] is then always zero.
    #[inline]
    pub fn is_specular(&self) -> bool {
        self.kind.is_specular()
    }

    /// The lobe width for the frequency operators; see [`MaterialKind::lobe`].
    #[inline]
    pub fn lobe(&self) -> Lobe {
        self.kind.lobe()
    }

    /// The albedo of a Lambertian BSDF (texture included), `None` for every other model: what
    /// the photon loop needs to decide its roulette before sampling.
    #[inline]
    pub fn lambertian_albedo(&self) -> Option<Rgb> {
        self.kind.lambertian_albedo()
    }

    /// f(outgoing, incoming) of `kind` about the unit `normal` (which faces its outside), as
    /// [`Bsdf::eval`] gives it: a Lambertian evaluated here, inline and without a frame (the
    /// photon gather's inner loop), every other model through [`Bsdf::eval`].
    #[inline]
    pub fn eval_about(kind: MaterialKind, normal: Vec3, outgoing: Vec3, incoming: Vec3) -> Rgb {
        match kind.lambertian_albedo() {
            Some(albedo) => diffuse::eval_world(albedo, normal, outgoing, incoming),
            None => Self::from_normal(kind, normal, true).eval(outgoing, incoming),
        }
    }

    /// The BSDF value f(outgoing, incoming), without the cosine; zero for delta lobes.
    pub fn eval(&self, outgoing: Vec3, incoming: Vec3) -> Rgb {
        let s = &self.shading;
        with_model!(self.kind, m => {
            if let Some(f) = m.eval_world(s, outgoing, incoming) {
                return f;
            }
            let frame = self.frame();
            let (wo, wi) = (frame.to_local(outgoing), frame.to_local(incoming));
            if transmits(&m) {
                return m.eval_through(s, wo, wi);
            }
            if wo.z * wi.z <= 0.0 {
                return Rgb::ZERO;
            }
            // Two-sided: mirror both into the upper hemisphere.
            let (wo, wi) = if wo.z < 0.0 { (-wo, -wi) } else { (wo, wi) };
            m.eval_local(s, wo, wi)
        })
    }

    /// Solid-angle density with which [`Bsdf::sample`] draws `incoming`; zero for delta lobes.
    pub fn pdf(&self, outgoing: Vec3, incoming: Vec3) -> f32 {
        let frame = self.frame();
        let (wo, wi) = (frame.to_local(outgoing), frame.to_local(incoming));
        with_model!(self.kind, m => {
            if transmits(&m) {
                return m.pdf_through(&self.shading, wo, wi);
            }
            if wo.z * wi.z <= 0.0 {
                return 0.0;
            }
            let (wo, wi) = if wo.z < 0.0 { (-wo, -wi) } else { (wo, wi) };
            m.pdf_local(wo, wi)
        })
    }

    /// Draws `incoming` for `outgoing` with `u_lobe` ∈ [0, 1) choosing a lobe (Fresnel reflection vs
    /// refraction, specular vs diffuse) and `u` ∈ [0, 1)² the direction; `None` when nothing is scattered.
    /// `mode` matters only for refraction (see [`TransportMode`]).
    pub fn sample(
        &self,
        outgoing: Vec3,
        u_lobe: f32,
        u: Vec2,
        mode: TransportMode,
    ) -> Option<BsdfSample> {
        let frame = self.frame();
        let wo = frame.to_local(outgoing);
        if wo.z == 0.0 || !wo.is_finite() {
            return None;
        }
        with_model!(self.kind, m => m.sample_local(&self.shading, &frame, wo, u_lobe, u, mode))
    }

    /// The densities of the lobes of finite density for the pair (see [`BsdfPdfs`]): `forward`
    /// is [`Bsdf::pdf`]`(outgoing, incoming)` and `reverse` is `pdf(incoming, outgoing)`, bit for
    /// bit; both zero from delta lobes, which a given pair of directions almost never meets (a
    /// sampled delta event's probabilities come with [`Bsdf::sample_with_pdfs`]).
    pub fn pdfs(&self, outgoing: Vec3, incoming: Vec3) -> BsdfPdfs {
        let frame = self.frame();
        let (wo, wi) = (frame.to_local(outgoing), frame.to_local(incoming));
        let s = &self.shading;
        let (forward, reverse) = with_model!(self.kind, m => {
            if transmits(&m) {
                (m.pdf_through(s, wo, wi), m.pdf_through(s, wi, wo))
            } else if wo.z * wi.z <= 0.0 {
                (0.0, 0.0)
            } else {
                // The flip of `pdf`, which mirrors both directions whichever comes first.
                let (wo, wi) = if wo.z < 0.0 { (-wo, -wi) } else { (wo, wi) };
                (m.pdf_local(wo, wi), m.pdf_local(wi, wo))
            }
        });
        BsdfPdfs {
            forward,
            reverse,
            is_specular: false,
        }
    }

    /// [`Bsdf::sample`] with the densities of the event it drew (see [`BsdfPdfs`]): the same
    /// sample for the same arguments, bit for bit; `forward` is its `pdf`, `reverse` the density
    /// of drawing `outgoing` from its `incoming`: [`Bsdf::pdf`]`(incoming, outgoing)` for a lobe of
    /// finite density, [`Bsdf::specular_probability`]`(incoming, …)` of the same lobe for a delta
    /// one.
    pub fn sample_with_pdfs(
        &self,
        outgoing: Vec3,
        u_lobe: f32,
        u: Vec2,
        mode: TransportMode,
    ) -> Option<(BsdfSample, BsdfPdfs)> {
        let sample = self.sample(outgoing, u_lobe, u, mode)?;
        let reverse = if sample.is_specular {
            self.specular_probability(sample.incoming, sample.is_transmission)
        } else {
            self.pdf(sample.incoming, outgoing)
        };
        let pdfs = BsdfPdfs {
            forward: sample.pdf,
            reverse,
            is_specular: sample.is_specular,
        };
        Some((sample, pdfs))
    }

    /// The probability that [`Bsdf::sample`] from `outgoing` picks a delta lobe: its refraction if
    /// `transmission`, else its reflection. It is the `pdf` of such a sample, computed the same
    /// way: one for a mirror (zero if it is black), Fresnel's R or 1 − R seen from the side of
    /// `outgoing` for a dielectric (1 − R is zero under total internal reflection), zero for
    /// models without delta lobes and for an `outgoing` in the tangent plane.
    pub fn specular_probability(&self, outgoing: Vec3, transmission: bool) -> f32 {
        let wo = self.frame().to_local(outgoing);
        if wo.z == 0.0 || !wo.is_finite() {
            return 0.0;
        }
        with_model!(self.kind, m => m.delta_probability(&self.shading, wo, transmission))
    }
}

/// Rec.709 luminance.
pub fn luminance(c: Rgb) -> f32 {
    c.dot(Vec3::new(0.2126, 0.7152, 0.0722))
}

/// Mirror of `w` about the unit normal `n` (both pointing away from the surface).
fn reflect(w: Vec3, n: Vec3) -> Vec3 {
    -w + 2.0 * w.dot(n) * n
}
