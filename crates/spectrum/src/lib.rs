//! The local light-field spectrum algebra behind frequency-photon progressive photon
//! mapping.
//!
//! This crate models the local spectrum of radiance around a ray as a 2D Gaussian over
//! space and angle frequencies, and transports it with closed-form arithmetic through
//! everything a photon meets: free space, curved mirrors, glossy and diffuse BRDFs,
//! refraction and partial occlusion. From the spectrum at a hitpoint it predicts the
//! radius of a density-estimation kernel that keeps the radiance essentially constant.
//! The frequency analysis is that of Durand, Holzschuch, Soler, Chan and Sillion, "A
//! Frequency Analysis of Light Transport" (SIGGRAPH 2005); the (a, b, c) model, the
//! radius formulas and the hitpoint merge are those of Belcour and Soler, "Frequency based
//! Kernel Estimation for Progressive Photon Mapping" (SIGGRAPH Asia 2011 poster).
//!
//! The principal type is [`Spectrum`], the poster's quadratic form (a, b, c). [`Caps`]
//! replaces every infinity with a finite bound, [`Lobe`] describes a BRDF, and
//! [`FrequencyEstimate`] is what a hitpoint stores. [`Covariance`] is the equivalent
//! Σ form of covariance tracing, kept for cross-checking. The crate depends only on
//! `std` and knows nothing about scenes, photons or threads.
//!
//! # Representation
//!
//! The flatland local light field L(x, θ) lives around a central ray of direction r.
//! Let p = rot90_CCW(r). A nearby ray has a signed offset **x** \[m\] along p, measured on the
//! line through the reference point perpendicular to r, and a counter-clockwise angle
//! **θ** \[rad\] from r. All frames are right-handed. To first order tan θ ≈ θ.
//!
//! The Fourier convention is l̂(Ω) = ∫ L(z) e^{−2πi Ωᵀz} dz with z = (x, θ) and
//! Ω = (Ωx \[cycles/m\], Ωθ \[cycles/rad\]). The spectrum is modelled as
//!
//! ```text
//! l̂(Ω) ∝ exp(−ΩᵀQΩ),   Q = [[a, c], [c, b]] ⪰ 0            (Spectrum: a [m²], b [rad²], c [m·rad])
//! Σ = (2Q)⁻¹ = [[b, −c], [−c, a]] / (2(ab − c²))            (Covariance: p, q, r)
//! L(z) ∝ exp(−π² zᵀQ⁻¹z),   P = Q/(2π²)                     (PrimalCovariance: the primal domain)
//! ```
//!
//! So Q is 2π² times the primal covariance of the light field: a *large* coefficient is a
//! *smooth* field. a is the Ωθ = 0 slice, i.e. the spectrum of the irradiance ∫L dθ, which
//! varies as exp(−π²x²/a). b is the same for the angular profile ∫L dx. The Schur
//! complement b − c²/a is the angular profile at a fixed position.
//!
//! | situation | Q form | Σ form |
//! |---|---|---|
//! | spatially constant | a → ∞ (a_max) | Σxx → 0 |
//! | spatial Dirac (point emitter) | a → 0 (a_min) | Σxx → ∞ |
//! | angularly constant (Lambertian) | b → ∞ (b_max), c = 0, flag set | Σθθ, Σxθ → 0 |
//! | angular Dirac (collimated) | b → 0 (b_min) | Σθθ → ∞ |
//!
//! # Operators
//!
//! A first-order ray map z' = M·z acts as **Q' = M Q Mᵀ** (and Σ' = M⁻ᵀ Σ M⁻¹,
//! det Q' = det(M)²·det Q; M and −M act alike). A primal multiplication (a window) is a
//! spectral convolution, so the covariances add: Σ' = Σ + W. A primal angular convolution
//! (a BRDF) is a spectral multiplication, so the forms add: Q' = Q + B. Every operator is
//! a method of [`Spectrum`] that takes `self` and the caps and returns a new value:
//!
//! | method | map | Q-form update |
//! |---|---|---|
//! | [`travel(d)`](Spectrum::travel) | T(d) = [[1, d], [0, 1]] | a' = a + 2dc + d²b, c' = c + db |
//! | [`kick(g)`](Spectrum::kick) | K(g) = [[1, 0], [g, 1]]; thin lens g = −1/f | c' = c + ga, b' = b + 2gc + g²a |
//! | [`project_in(μi)`](Spectrum::project_in) | D(1/μi, 1) | a' = a/μi², c' = c/μi |
//! | [`project_out(μo)`](Spectrum::project_out) | D(μo, 1) | a' = μo²a, c' = μo c |
//! | [`reflect(μi, μo, κ, lobe)`](Spectrum::reflect) | [[−μo/μi, 0], [2κ/μi, −1]], then the lobe | a' = m²a, c' = m(c − ga), b' = b − 2gc + g²a + 2π²σρ² (m = μo/μi, g = 2κ/μi) |
//! | [`refract(ηi, ηt, μi, μt, κ)`](Spectrum::refract) | [[t, 0], [h, s]]: s = ηiμi/(ηtμt), t = μt/μi, h = (1 − s)κ/μi | a' = t²a, c' = t(sc + ha), b' = s²b + 2shc + h²a |
//! | [`bandlimit(lobe)`](Spectrum::bandlimit) | angular convolution by the lobe | b' = b + 2π²σρ² (Lambert: b' = b_max, c' = 0) |
//! | [`occlude(o)`](Spectrum::occlude) | Σ' = Σ + diag(o, 0) | den = 1 + 2oa: a' = a/den, c' = c/den, b' = b − 2oc²/den |
//! | [`cosine(θi)`](Spectrum::cosine) (optional) | Σ' = Σ + diag(0, w_c), w_c = 1/max(π/2 − θi, ε)² | den = 1 + 2w_c b: b' = b/den, c' = c/den, a' = a − 2w_c c²/den |
//! | [`flip`](Spectrum::flip) | F = diag(1, −1) | c' = −c |
//!
//! μ = |cos θ| are cosines to the surface normal, κ \[1/m\] is the signed curvature in the
//! plane of incidence, positive when the centre of curvature is on the side the light
//! comes from (concave); σρ² \[rad²\] is the lobe's angular variance ([`Lobe`]: Phong 1/n,
//! Blinn–Phong 4/n, Beckmann 2α², GGX α²). With right-handed frames on both sides a flat
//! mirror leaves (a, b, c) unchanged; a left-handed outgoing frame would flip c instead,
//! and a point light seen in a flat mirror would then appear to travel backwards. A
//! concave mirror focuses a collimated beam at (R/2)·cos θ. Refraction scales det Q by
//! (ηi/ηt)². The Woodbury forms of `occlude` and `cosine` have denominators ≥ 1, so no
//! inverse is ever taken.
//!
//! # Emitters
//!
//! The initial spectrum in the emitted ray frame (a box of width w counts as a Gaussian of
//! variance w²/12):
//!
//! | constructor | a | b |
//! |---|---|---|
//! | [`area_light(s, μe)`](Spectrum::area_light) | (π²/6)·s²·μe² | b_max (Lambertian) |
//! | [`point_light`](Spectrum::point_light) | a_min | b_max (Lambertian) |
//! | [`spot_light(θs)`](Spectrum::spot_light) (hard cone) | a_min | 2π²θs²/3 |
//! | [`spot_light_falloff(m)`](Spectrum::spot_light_falloff) (cosᵐ) | a_min | 2π²/m |
//! | [`directional_light`](Spectrum::directional_light) | a_max | b_min |
//! | [`sun(δ)`](Spectrum::sun) | a_max | π²δ²/6 |
//!
//! c = 0 for all of them.
//!
//! # Kernel radii
//!
//! With β₉₅ = −ln 0.95 and a radius constant K:
//!
//! ```text
//! r_x = K·√a                      (spatial_radius)
//! r_θ = z·tan(K·√b)               (angular_radius; +∞ once K·√b ≥ π/2, and for Lambertian fields)
//! r_freq = min(r_x, r_θ)          (Spectrum::radius, FrequencyEstimate::radius)
//! a_cam = (ab − c²)/(b + 2c/D + a/D²),  r_cam = K·√a_cam / μo     (optional camera line)
//! ```
//!
//! z is the camera distance projected on the hitpoint normal. Two constants are provided.
//! [`K_POSTER`] = π·√β₉₅ ≈ 0.7115 reproduces the poster; it equals 3.16 primal standard
//! deviations of the irradiance. [`K_STRICT`] = √β₉₅/π ≈ 0.0721 is the radius at which
//! exp(−π²x²/a) actually falls to 95 % of its peak (0.32 σ). They differ by exactly π²,
//! which suggests the poster's inverse transform put π² in the denominator. The slices a
//! and b ignore the space–angle correlation, so a small light on a glossy plane gets large
//! radii although its highlight is sharp. The camera-line bandwidth a_cam restricts the
//! reflected field to the rays that reach a camera at distance D and catches that case;
//! use min(r_x, r_θ, r_cam) when the slices blur highlights.
//!
//! # Merging deposits at a hitpoint
//!
//! A [`FrequencyEstimate`] starts empty (`has_freq` false: the hitpoint shrinks like
//! standard PPM) and merges every frequency photon deposited into its kernel under a
//! [`MergePolicy`]. [`MergePolicy::MinRadius`], the default, keeps min(a) and min(b),
//! which is exactly the smallest radius any deposit predicts. [`MergePolicy::PosterMax`]
//! keeps the per-coefficient max, as the poster states. The two differ because r_x grows
//! with a and r_θ with b: the max picks the *smoothest* photon, the least conservative
//! choice, while the min is the conservative one. (A per-coefficient min of c would break
//! PSD, which is why `MinRadius` drops c.) Deposit the field reflected toward the camera,
//! `reflect(μi, 1.0, κ, lobe)` with the hitpoint's curvature and lobe: with μo = 1 its a is
//! in surface units (the kernel's), and b does not depend on μo. A Lambertian hitpoint
//! then has an infinite r_θ and only r_x matters. (The camera-line radius needs the field
//! in the camera's ray frame: `reflect(μi, μ_cam, κ, lobe)`.) The PPM radius/flux update
//! belongs to the renderer.
//!
//! # Caps
//!
//! Infinities are replaced by [`Caps`], applied after every operator: a is clamped to
//! [a_min, a_max], b to [b_min, b_max], then c into c² ≤ a·b·(1 − 10⁻¹²). The caps are
//! primal scales: [`Caps::for_scene_size(L)`](Caps::for_scene_size) sets a_max = 2π²L²,
//! a_min = 2π²(10⁻⁴L)², b_max = 2π²·(1 rad)², b_min = 2π²·(10⁻⁴ rad)² (suggested values,
//! not from the poster). A capped b_max is the ±1 rad analysis window: a point light's
//! irradiance after travel d has a ≈ d²·b_max, a width ≈ d·1 rad. Cosines are clamped to
//! μ ≥ [`MU_MIN`] = 10⁻⁴, overflow (∞ − ∞) resolves to the cap, and no operator ever
//! returns a NaN, even for NaN parameters. Lambertian fields carry a flag rather than a
//! sentinel value. The caps are passed to each operator as `&Caps` (four numbers shared
//! by all photons); [`Caps::UNBOUNDED`] switches them off for exact algebra.
//!
//! # Using the flatland algebra in 3D
//!
//! The poster assumes the 4D spectrum is isotropic in space and in angle, so one (x, θ)
//! pair stands for both tangent axes. Travel and BRDFs keep that isotropy; projection
//! (only the in-plane axis is foreshortened) and anisotropic curvature do not. The
//! conservative collapse keeps, per coefficient, the variant with the smaller a and b.
//! Projection in therefore leaves a unchanged: skip `project_in`, or use
//! [`Spectrum::reflect_isotropic`], which is `reflect` with μi = 1. Projection out applies
//! μo²·a as usual. For κ, use |κ|max or the mean curvature, whichever gives the smaller
//! result.
//!
//! # Example
//!
//! A point light 1 m from a flat mirror, seen 2 m after the bounce, is a point light 3 m
//! away (the virtual image). The spectrum then reaches a diffuse floor.
//!
//! ```
//! use spectrum::{Caps, K_POSTER, Lobe, Spectrum};
//!
//! let caps = Caps::for_scene_size(10.0);
//! let light = Spectrum::point_light(&caps);
//! let mirrored = light
//!     .travel(1.0, &caps)
//!     .reflect(0.7, 0.7, 0.0, Lobe::Mirror, &caps)
//!     .travel(2.0, &caps);
//! let direct = light.travel(3.0, &caps);
//! assert!((mirrored.a() - direct.a()).abs() < 1e-9 * direct.a());
//!
//! // On a diffuse floor at 45°, seen from 2 m: only the spatial radius limits the kernel.
//! let floor = mirrored.reflect(0.7071, 1.0, 0.0, Lobe::Lambert, &caps);
//! assert!(floor.is_lambertian());
//! assert_eq!(floor.radius(2.0, K_POSTER), floor.spatial_radius(K_POSTER));
//! ```

mod caps;
mod covariance;
mod emitters;
mod estimate;
mod lobe;
mod radius;
mod spectrum;

pub use caps::{Caps, MU_MIN};
pub use covariance::Covariance;
pub use estimate::{FrequencyEstimate, MergePolicy};
pub use lobe::Lobe;
pub use radius::{BETA_95, K_POSTER, K_STRICT, angular_radius, spatial_radius};
pub use spectrum::{PrimalCovariance, Spectrum, refracted_cosine};
