//! The Q form (a, b, c): the principal type and its operators.

use std::f64::consts::FRAC_PI_2;

use crate::caps::{Caps, TWO_PI_SQ, clamp_eta, clamp_mu, det2, harmonic, overflow_to_inf};
use crate::covariance::Covariance;
use crate::lobe::Lobe;
use crate::radius::{angular_radius, spatial_radius};

/// The local light-field spectrum `l̂(Ωx, Ωθ) ∝ exp(−(a·Ωx² + 2c·ΩxΩθ + b·Ωθ²))`, stored
/// as the poster's quadratic form Q = [[a, c], [c, b]] in `f64`.
///
/// Units: a \[m²\], b \[rad²\], c \[m·rad\]. Q = 2π²·P where P is the primal covariance of the
/// light field over (x, θ), so a larger coefficient means a *smoother* field.
///
/// Invariants, kept by every constructor and operator (see [`Caps`]): a and b lie inside
/// the caps, `c² ≤ a·b·(1 − 10⁻¹²)`, nothing is NaN, and a Lambertian value has
/// b = b_max and c = 0.
///
/// Operators take `self` by value and return the transformed spectrum, capped by the
/// `&Caps` they are given.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Spectrum {
    a: f64,
    b: f64,
    c: f64,
    lambertian: bool,
}

/// The primal covariance P = Q/(2π²) of the light field over (x \[m\], θ \[rad\]).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PrimalCovariance {
    /// Var(x) \[m²\].
    pub xx: f64,
    /// Cov(x, θ) \[m·rad\].
    pub xt: f64,
    /// Var(θ) \[rad²\].
    pub tt: f64,
}

impl Spectrum {
    /// A spectrum from its coefficients, capped by `caps`.
    ///
    /// Infinite a or b land on the caps. `None` for a NaN, a negative a or b, or a form
    /// that is not positive semi-definite (`c² > a·b` beyond rounding).
    #[must_use]
    pub fn new(a: f64, b: f64, c: f64, caps: &Caps) -> Option<Self> {
        let psd = c * c <= a * b * (1.0 + 1e-9);
        (a >= 0.0 && b >= 0.0 && !c.is_nan() && psd).then(|| Self::finish(a, b, c, false, caps))
    }

    /// The exact bits of (a, b, c, Lambertian flag), for storing a spectrum (checkpoints).
    /// [`Spectrum::from_bits`] restores the identical value.
    #[must_use]
    pub fn to_bits(&self) -> [u64; 4] {
        [
            self.a.to_bits(),
            self.b.to_bits(),
            self.c.to_bits(),
            u64::from(self.lambertian),
        ]
    }

    /// The spectrum stored by [`Spectrum::to_bits`], bit for bit (no caps are applied again).
    /// `None` if the bits do not describe a valid spectrum: NaN, negative a or b, c² > a·b, or
    /// a flag other than 0 or 1.
    #[must_use]
    pub fn from_bits(bits: [u64; 4]) -> Option<Self> {
        let [a, b, c] = [bits[0], bits[1], bits[2]].map(f64::from_bits);
        let lambertian = match bits[3] {
            0 => false,
            1 => true,
            _ => return None,
        };
        let valid = a >= 0.0 && b >= 0.0 && !c.is_nan() && c * c <= a * b;
        valid.then_some(Spectrum {
            a,
            b,
            c,
            lambertian,
        })
    }

    /// A spectrum from the primal covariance P of the light field: Q = 2π²·P.
    /// `None` under the conditions of [`Spectrum::new`].
    #[must_use]
    pub fn from_primal_covariance(primal: PrimalCovariance, caps: &Caps) -> Option<Self> {
        Self::new(
            TWO_PI_SQ * primal.xx,
            TWO_PI_SQ * primal.tt,
            TWO_PI_SQ * primal.xt,
            caps,
        )
    }

    /// A spectrum from its spectral covariance Σ: Q = (2Σ)⁻¹, i.e.
    /// `a = r/(2Δ)`, `b = p/(2Δ)`, `c = −q/(2Δ)` with Δ = pr − q².
    /// `None` when Σ is singular.
    #[must_use]
    pub fn from_covariance(covariance: Covariance, caps: &Caps) -> Option<Self> {
        let (p, q, r) = (covariance.p(), covariance.q(), covariance.r());
        let det = det2(p, r, q, q);
        if det.is_nan() || det <= 0.0 {
            return None;
        }
        let s = 0.5 / det;
        Self::new(r * s, p * s, -q * s, caps)
    }

    /// The spatial coefficient a \[m²\]: the irradiance ∫L dθ varies as exp(−π²x²/a).
    #[must_use]
    pub fn a(&self) -> f64 {
        self.a
    }

    /// The angular coefficient b \[rad²\]: ∫L dx varies as exp(−π²θ²/b).
    #[must_use]
    pub fn b(&self) -> f64 {
        self.b
    }

    /// The cross coefficient c \[m·rad\] (space–angle correlation).
    #[must_use]
    pub fn c(&self) -> f64 {
        self.c
    }

    /// True when the field is angularly flat (Lambertian): b stands for +∞ (stored as
    /// b_max) and c = 0. Set by [`Lobe::Lambert`] and by the angularly flat emitters;
    /// kept by the projections, occlusion and band-limits; cleared by every operator that
    /// mixes space into angle or narrows the angular content.
    #[must_use]
    pub fn is_lambertian(&self) -> bool {
        self.lambertian
    }

    /// det Q = a·b − c² \[m²·rad²\], computed with one rounding error.
    #[must_use]
    pub fn determinant(&self) -> f64 {
        det2(self.a, self.b, self.c, self.c)
    }

    /// The primal covariance P = Q/(2π²).
    #[must_use]
    pub fn primal_covariance(&self) -> PrimalCovariance {
        PrimalCovariance {
            xx: self.a / TWO_PI_SQ,
            xt: self.c / TWO_PI_SQ,
            tt: self.b / TWO_PI_SQ,
        }
    }

    /// The spectral covariance Σ = (2Q)⁻¹ = [[b, −c], [−c, a]] / (2(ab − c²)), or `None`
    /// when Q is singular (only possible with a zero cap, e.g. [`Caps::UNBOUNDED`]).
    #[must_use]
    pub fn covariance(&self) -> Option<Covariance> {
        let det = self.determinant();
        if det.is_nan() || det <= 0.0 {
            return None;
        }
        let s = 0.5 / det;
        Covariance::new(self.b * s, -self.c * s, self.a * s)
    }

    /// The same coefficients under other caps (capping is idempotent:
    /// `s.capped(caps).capped(caps) == s.capped(caps)`).
    #[must_use]
    pub fn capped(self, caps: &Caps) -> Self {
        Self::finish(self.a, self.b, self.c, self.lambertian, caps)
    }

    // ----------------------------------------------------------------------------------
    // Operators.

    /// Travel in free space by d \[m\]: T(d) = [[1, d], [0, 1]] (x' = x + d·θ), Q' = T Q Tᵀ:
    ///
    /// `a' = a + 2d·c + d²·b`, `c' = c + d·b`, `b' = b`.
    ///
    /// Spatial content is sheared into angle; from a capped (diffuse) b the irradiance
    /// smooths as a' ≈ d²·b_max. Exact composition T(d₁)T(d₂) = T(d₁ + d₂), T(d)T(−d) = I.
    #[must_use]
    pub fn travel(self, distance: f64, caps: &Caps) -> Self {
        let d = distance;
        let a = overflow_to_inf(self.a + d * (2.0 * self.c + d * self.b));
        let c = self.c + d * self.b;
        Self::finish(a, self.b, c, self.lambertian && d == 0.0, caps)
    }

    /// Angular kick by g \[rad/m\]: K(g) = [[1, 0], [g, 1]] (θ' = θ + g·x), Q' = K Q Kᵀ:
    ///
    /// `a' = a`, `c' = c + g·a`, `b' = b + 2g·c + g²·a`.
    ///
    /// A thin lens of focal length f is the kick g = −1/f; a curved interface is a kick by
    /// its curvature in the surface frame. K(g)K(−g) = I.
    #[must_use]
    pub fn kick(self, g: f64, caps: &Caps) -> Self {
        let b = overflow_to_inf(self.b + g * (2.0 * self.c + g * self.a));
        let c = self.c + g * self.a;
        Self::finish(self.a, b, c, self.lambertian && g == 0.0, caps)
    }

    /// Angle flip F = diag(1, −1): `c' = −c`.
    ///
    /// This is the mirror about the local normal *with the outgoing frame left-handed*.
    /// [`Spectrum::reflect`] already contains it (with right-handed frames a flat mirror
    /// leaves (a, b, c) unchanged); use `flip` only to compose chains by hand. F∘F = I.
    #[must_use]
    pub fn flip(self, caps: &Caps) -> Self {
        Self::finish(self.a, self.b, -self.c, self.lambertian, caps)
    }

    /// Projection from the ray frame onto a surface hit at cosine μi = |cos θi|:
    /// D(1/μi, 1) (surface coordinate u = x/μi):
    ///
    /// `a' = a/μi²`, `c' = c/μi`, `b' = b`.
    ///
    /// μi is clamped to [[`MU_MIN`](crate::MU_MIN), 1]. For the conservative 3D collapse
    /// skip this operator (the out-of-plane axis is not stretched); see the crate docs.
    #[must_use]
    pub fn project_in(self, mu_i: f64, caps: &Caps) -> Self {
        let inv = 1.0 / clamp_mu(mu_i);
        Self::finish(
            self.a * inv * inv,
            self.b,
            self.c * inv,
            self.lambertian,
            caps,
        )
    }

    /// Projection from a surface back to the ray frame leaving at cosine μo = |cos θo|:
    /// D(μo, 1):
    ///
    /// `a' = μo²·a`, `c' = μo·c`, `b' = b`.
    ///
    /// μo is clamped to [[`MU_MIN`](crate::MU_MIN), 1].
    #[must_use]
    pub fn project_out(self, mu_o: f64, caps: &Caps) -> Self {
        let mu = clamp_mu(mu_o);
        Self::finish(self.a * mu * mu, self.b, self.c * mu, self.lambertian, caps)
    }

    /// Complete reflection in right-handed frames: projection in at μi, kick −κ, angle
    /// flip, kick +κ, projection out at μo, then the BRDF band-limit:
    ///
    /// R = D(−μo, 1)·K(κ)·F·K(−κ)·D(1/μi, 1) = [[−μo/μi, 0], [2κ/μi, −1]].
    ///
    /// With m = μo/μi and g = 2κ/μi:
    /// `a' = m²·a`, `c' = m·(c − g·a)`, `b' = b − 2g·c + g²·a + 2π²σρ²`.
    ///
    /// κ \[1/m\] is the signed curvature in the plane of incidence, positive when the centre
    /// of curvature lies on the side the light comes from (concave, focusing). A flat
    /// mirror (κ = 0, μo = μi, [`Lobe::Mirror`]) leaves (a, b, c) unchanged; a concave
    /// mirror focuses a collimated beam at (R/2)·cos θ. For glossy lobes pass the cosine
    /// of the *sampled* outgoing direction. Cosines are clamped to
    /// [[`MU_MIN`](crate::MU_MIN), 1].
    #[must_use]
    pub fn reflect(self, mu_i: f64, mu_o: f64, curvature: f64, lobe: Lobe, caps: &Caps) -> Self {
        let inv_mu_i = 1.0 / clamp_mu(mu_i);
        let m = clamp_mu(mu_o) * inv_mu_i;
        let g = 2.0 * curvature * inv_mu_i;
        let a = m * m * self.a;
        let c = m * (self.c - g * self.a);
        let b = overflow_to_inf(self.b + g * (g * self.a - 2.0 * self.c));
        match lobe.bandwidth() {
            None => Self::finish(a, b, c, true, caps),
            Some(b_rho) => Self::finish(a, b + b_rho, c, false, caps),
        }
    }

    /// The reflections of the two tangent axes (design §8.5), `[tangential, sagittal]`:
    ///
    /// - in the plane of incidence (tangential), [`Spectrum::reflect`] itself: the
    ///   footprint scales by m = μo/μi and the curvature kicks by g = 2κ/μi;
    /// - across it (sagittal), nothing is foreshortened (m = 1) and the curvature kicks by
    ///   g = 2κ·μi (a concave mirror focuses a collimated beam at R/(2μi) there, at R·μi/2
    ///   in the plane); the lobe adds the same b_ρ.
    ///
    /// Neither axis alone is conservative, and no single Gaussian lies below both after
    /// every travel distance, so a photon carries both to its next hit and keeps the sharper
    /// there ([`Spectrum::sharper`]). Pass the curvature that focuses most from the arriving
    /// side (the largest principal curvature, positive when concave).
    #[must_use]
    pub fn reflect_axes(
        self,
        mu_i: f64,
        mu_o: f64,
        curvature: f64,
        lobe: Lobe,
        caps: &Caps,
    ) -> [Self; 2] {
        let mu_i = clamp_mu(mu_i);
        let tangential = self.reflect(mu_i, mu_o, curvature, lobe, caps);
        let g = 2.0 * curvature * mu_i;
        let a = self.a;
        let c = self.c - g * self.a;
        let b = overflow_to_inf(self.b + g * (g * self.a - 2.0 * self.c));
        let sagittal = match lobe.bandwidth() {
            None => Self::finish(a, b, c, true, caps),
            Some(b_rho) => Self::finish(a, b + b_rho, c, false, caps),
        };
        [tangential, sagittal]
    }

    /// The field on the surface under the conservative 3D collapse (design §8.5): of the two
    /// axes of [`Spectrum::reflect_axes`], the smaller a and the smaller b, with c capped
    /// into a semi-definite form. Right at the surface (no travel) this predicts no larger a
    /// kernel than either axis: it is what a hitpoint reads from a photon.
    #[must_use]
    pub fn reflect_isotropic(
        self,
        mu_i: f64,
        mu_o: f64,
        curvature: f64,
        lobe: Lobe,
        caps: &Caps,
    ) -> Self {
        let [t, s] = self.reflect_axes(mu_i, mu_o, curvature, lobe, caps);
        Self::finish(
            t.a.min(s.a),
            t.b.min(s.b),
            t.c.min(s.c),
            t.lambertian && s.lambertian,
            caps,
        )
    }

    /// Of two forms, the one that predicts the smaller kernel here: the smaller a (then the
    /// smaller b). Used where a photon that carried both axes' spectra arrives at a surface.
    #[must_use]
    pub fn sharper(self, other: Self) -> Self {
        if (other.a, other.b) < (self.a, self.b) {
            other
        } else {
            self
        }
    }

    /// Refraction through a smooth interface from index ηi to ηt, at incident and
    /// transmitted cosines μi, μt, with signed curvature κ \[1/m\] (as in
    /// [`Spectrum::reflect`]):
    ///
    /// R_t = [[t, 0], [h, s]] with s = ηi·μi/(ηt·μt), t = μt/μi, h = (1 − s)·κ/μi;
    /// `a' = t²·a`, `c' = t·(s·c + h·a)`, `b' = s²·b + 2s·h·c + h²·a`.
    ///
    /// First-order Snell (ηi·μi·δθi = ηt·μt·δθt) scales angles by s and the footprint by
    /// t; det Q' = (ηi/ηt)²·det Q (étendue). Total internal reflection has no transmitted
    /// field: check it with [`refracted_cosine`] first. Cosines
    /// are clamped to [[`MU_MIN`](crate::MU_MIN), 1], indices to [10⁻³, 10³].
    #[must_use]
    pub fn refract(
        self,
        eta_i: f64,
        eta_t: f64,
        mu_i: f64,
        mu_t: f64,
        curvature: f64,
        caps: &Caps,
    ) -> Self {
        let (mu_i, mu_t) = (clamp_mu(mu_i), clamp_mu(mu_t));
        let s = clamp_eta(eta_i) * mu_i / (clamp_eta(eta_t) * mu_t);
        let t = mu_t / mu_i;
        let h = (1.0 - s) * curvature / mu_i;
        let a = t * t * self.a;
        let c = t * (s * self.c + h * self.a);
        let b = overflow_to_inf(s * s * self.b + h * (2.0 * s * self.c + h * self.a));
        Self::finish(a, b, c, false, caps)
    }

    /// The refractions of the two tangent axes (design §8.5), `[tangential, sagittal]`: the
    /// tangential one is [`Spectrum::refract`]; across the plane of incidence nothing is
    /// foreshortened (t = 1), angles scale by s = ηi/ηt and the curvature kicks by
    /// h = (ηt·μt − ηi·μi)·κ/ηt (Coddington's oblique power, in reduced angles). As for
    /// [`Spectrum::reflect_axes`], a photon carries both to its next hit.
    #[must_use]
    pub fn refract_axes(
        self,
        eta_i: f64,
        eta_t: f64,
        mu_i: f64,
        mu_t: f64,
        curvature: f64,
        caps: &Caps,
    ) -> [Self; 2] {
        let tangential = self.refract(eta_i, eta_t, mu_i, mu_t, curvature, caps);
        let (eta_i, eta_t) = (clamp_eta(eta_i), clamp_eta(eta_t));
        let (mu_i, mu_t) = (clamp_mu(mu_i), clamp_mu(mu_t));
        let s = eta_i / eta_t;
        let h = (eta_t * mu_t - eta_i * mu_i) * curvature / eta_t;
        let a = self.a;
        let c = s * self.c + h * self.a;
        let b = overflow_to_inf(s * s * self.b + h * (2.0 * s * self.c + h * self.a));
        [tangential, Self::finish(a, b, c, false, caps)]
    }

    /// BRDF band-limit: the outgoing field is the incoming one convolved in angle with
    /// the lobe (a primal convolution, so a spectral multiplication: the forms add):
    ///
    /// `b' = b + 2π²σρ²`, `a' = a`, `c' = c`.
    ///
    /// [`Lobe::Mirror`] is a no-op; [`Lobe::Lambert`] (σρ = ∞) sets b' = b_max, c' = 0 and
    /// the Lambertian flag, keeping a (the irradiance spectrum).
    #[must_use]
    pub fn bandlimit(self, lobe: Lobe, caps: &Caps) -> Self {
        match lobe.bandwidth() {
            None => Self::finish(self.a, self.b, 0.0, true, caps),
            Some(b_rho) => Self::finish(self.a, self.b + b_rho, self.c, self.lambertian, caps),
        }
    }

    /// Partial occlusion by a window in the current plane with spectral variance o \[m⁻²\]
    /// (a primal multiplication, so a spectral convolution: Σ' = Σ + diag(o, 0)). In Q
    /// form, with den = 1 + 2o·a:
    ///
    /// `a' = a/den`, `c' = c/den`, `b' = b − 2o·c²/den`.
    ///
    /// For a Gaussian window of primal width w \[m\], o = 1/(4π²w²). A blocker at distance
    /// t inside a segment of length d is `travel(t)`, `occlude(o)`, `travel(d − t)`.
    /// Negative o counts as 0.
    #[must_use]
    pub fn occlude(self, o: f64, caps: &Caps) -> Self {
        let x = 2.0 * o.max(0.0) * self.a;
        let (a, b, c) = harmonic(self.a, self.b, self.c, x);
        Self::finish(a, b, c, self.lambertian, caps)
    }

    /// The optional cosine term of covariance tracing (not in the poster): Σ' = Σ +
    /// diag(0, w_c) with w_c = 1/max(π/2 − θi, 10⁻¹⁰)² \[rad⁻²\]. In Q form, with
    /// den = 1 + 2w_c·b:
    ///
    /// `b' = b/den`, `c' = c/den`, `a' = a − 2w_c·c²/den`.
    ///
    /// θi \[rad\] is the incidence angle |θi| ∈ [0, π/2].
    #[must_use]
    pub fn cosine(self, theta_i: f64, caps: &Caps) -> Self {
        let gap = (FRAC_PI_2 - theta_i.abs()).max(1e-10);
        let w_c = 1.0 / (gap * gap);
        let (b, a, c) = harmonic(self.b, self.a, self.c, 2.0 * w_c * self.b);
        Self::finish(a, b, c, false, caps)
    }

    // ----------------------------------------------------------------------------------
    // Kernel radii.

    /// Spatial radius `r_x = K·√a` \[m\], see [`spatial_radius`].
    #[must_use]
    pub fn spatial_radius(&self, k: f64) -> f64 {
        spatial_radius(self.a, k)
    }

    /// Angular radius `r_θ = z·tan(K·√b)` \[m\] (+∞ once K·√b ≥ π/2, and for a Lambertian
    /// spectrum), see [`angular_radius`]. `normal_distance` z \[m\]
    /// is the camera distance projected on the hitpoint normal.
    #[must_use]
    pub fn angular_radius(&self, normal_distance: f64, k: f64) -> f64 {
        if self.lambertian {
            f64::INFINITY
        } else {
            angular_radius(self.b, normal_distance, k)
        }
    }

    /// The poster's kernel radius `r_freq = min(r_x, r_θ)` \[m\].
    #[must_use]
    pub fn radius(&self, normal_distance: f64, k: f64) -> f64 {
        self.spatial_radius(k)
            .min(self.angular_radius(normal_distance, k))
    }

    /// The field restricted to the rays that converge to a camera at distance D \[m\]
    /// (θ = −x/D in this frame), as an a-like bandwidth \[m²\]:
    ///
    /// `a_cam = (a·b − c²) / (b + 2c/D + a/D²)`.
    ///
    /// Apply it to the *reflected* spectrum toward the camera. Unlike the slices a and b it
    /// sees the space–angle correlation, e.g. the sharp glossy highlight of a small light:
    /// point light at d, Phong lobe b_ρ, camera at D gives a_cam → b_ρ·(dD/(d + D))².
    /// For a Lambertian spectrum a_cam → a. D = +∞ gives the Schur complement (ab − c²)/b.
    #[must_use]
    pub fn camera_line_bandwidth(&self, camera_distance: f64) -> f64 {
        let inv_d = 1.0 / camera_distance.abs().max(1e-300);
        let den = self.b + inv_d * (2.0 * self.c + inv_d * self.a);
        let det = self.determinant().max(0.0);
        if den > 0.0 && den.is_finite() {
            det / den
        } else {
            0.0
        }
    }

    /// The optional camera-line radius `r_cam = K·√a_cam / μo` \[m\] on the surface, with
    /// a_cam from [`Spectrum::camera_line_bandwidth`] and μo the cosine toward the camera
    /// (clamped to [[`MU_MIN`](crate::MU_MIN), 1]). Use `min(r_x, r_θ, r_cam)` if the
    /// poster-literal radius blurs highlights.
    #[must_use]
    pub fn camera_line_radius(&self, camera_distance: f64, mu_o: f64, k: f64) -> f64 {
        spatial_radius(self.camera_line_bandwidth(camera_distance), k) / clamp_mu(mu_o)
    }

    /// The field as a hitpoint seen at cosine μo from a camera at distance D reads it: a
    /// lowered to `min(a, a_cam/μo²)` (see [`Spectrum::camera_line_radius`]), so that the
    /// spatial radius of the result is min(r_x, r_cam). Computed per deposit, while the
    /// deposit still has its space–angle correlation c (the min-radius merge drops it, and
    /// without c the camera-line radius is never the smaller). Lambertian fields are returned
    /// unchanged (their r_cam ≥ r_x).
    #[must_use]
    pub fn seen_along_camera_line(self, camera_distance: f64, mu_o: f64, caps: &Caps) -> Self {
        if self.lambertian {
            return self;
        }
        let mu = clamp_mu(mu_o);
        let a_cam = self.camera_line_bandwidth(camera_distance) / (mu * mu);
        if a_cam >= self.a {
            return self;
        }
        Self::finish(a_cam, self.b, self.c, false, caps)
    }

    // ----------------------------------------------------------------------------------
    // Internals.

    /// The same spectrum with c = 0 (for the min-radius merge).
    pub(crate) fn without_correlation(self) -> Self {
        Spectrum { c: 0.0, ..self }
    }

    /// Per-coefficient min of a and b, c = 0; Lambertian only if both are.
    pub(crate) fn merge_min(self, other: Self) -> Self {
        Spectrum {
            a: self.a.min(other.a),
            b: self.b.min(other.b),
            c: 0.0,
            lambertian: self.lambertian && other.lambertian,
        }
    }

    /// Per-coefficient max of (a, b, c); Lambertian (b = +∞, hence c = 0) if either is.
    /// Stays PSD: |max c| ≤ √(max a · max b).
    pub(crate) fn merge_max(self, other: Self) -> Self {
        let lambertian = self.lambertian || other.lambertian;
        Spectrum {
            a: self.a.max(other.a),
            b: self.b.max(other.b),
            c: if lambertian { 0.0 } else { self.c.max(other.c) },
            lambertian,
        }
    }

    /// Applies the caps (and the Lambertian normal form) to raw coefficients.
    pub(crate) fn finish(a: f64, b: f64, c: f64, lambertian: bool, caps: &Caps) -> Self {
        let (a, b, c) = if lambertian {
            (a, caps.b_max(), 0.0)
        } else {
            caps.window_angles(a, b, c)
        };
        let (a, b, c) = caps.clamp(a, b, c);
        debug_assert!(
            a >= 0.0 && b >= 0.0 && c * c <= a * b,
            "non-PSD ({a}, {b}, {c})"
        );
        Spectrum {
            a,
            b,
            c,
            lambertian,
        }
    }
}

/// The transmitted cosine μt = √(1 − (ηi/ηt)²·(1 − μi²)) by Snell's law, or `None` under
/// total internal reflection (or for a non-positive index).
#[must_use]
pub fn refracted_cosine(eta_i: f64, eta_t: f64, mu_i: f64) -> Option<f64> {
    if !(eta_i > 0.0 && eta_t > 0.0) {
        return None;
    }
    let ratio = eta_i / eta_t;
    let mu_i = mu_i.abs().min(1.0);
    let sin_t_sq = ratio * ratio * (1.0 - mu_i * mu_i);
    (sin_t_sq <= 1.0).then(|| (1.0 - sin_t_sq).sqrt())
}
