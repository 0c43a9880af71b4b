//! Spectra to linear Rec.709 RGB, as Mitsuba 3 does in its RGB variants, and the RGB
//! complex indices of refraction of Mitsuba's named conductors.
//!
//! [`spectrum_to_rgb`] follows `spectrum_list_to_srgb` (Mitsuba 3, `src/core/spectrum.cpp`):
//! the piecewise-linear spectrum is sampled at 1000 wavelengths evenly spread over
//! [360, 830] nm (zero outside its own range), weighted by the CIE 1931 2° colour-matching
//! functions (and by the D65 illuminant for everything but emission), scaled by 1/106.75 (the
//! integral of ȳ), and converted from XYZ to linear sRGB. Reflectances are clamped to [0, 1],
//! emission and indices of refraction only to ≥ 0. (Mitsuba's *named* conductors are read
//! from files without the D65 weighting; [`METALS`] holds what it loads for them.) The colour-matching functions are the CIE
//! 1931 tables at 5 nm, as Mitsuba stores them (read back through `mi.cie1931_xyz`).

use glam::DVec3;

use scene::Rgb;

/// First wavelength of the tables, nm.
const CIE_MIN: f64 = 360.0;
/// Last wavelength of the tables, nm.
const CIE_MAX: f64 = 830.0;
/// Integral of ȳ over [360, 830] nm (Mitsuba's `MI_CIE_Y_NORMALIZATION` is its inverse).
const CIE_Y_INTEGRAL: f64 = 106.750_259_399_414_06;
/// Mitsuba's `MI_CIE_D65_NORMALIZATION` is the inverse of this.
const D65_NORMALIZATION: f64 = 98.997_417_518_762_55;

/// CIE 1931 x̄ at 360, 365, …, 830 nm.
const CIE_X: [f64; 95] = [
    0.0001299,
    0.000232100007,
    0.000414899987,
    0.000741600001,
    0.00136800006,
    0.00223600003,
    0.00424299994,
    0.00765000004,
    0.0143100005,
    0.0231899992,
    0.0435100012,
    0.0776299983,
    0.134379998,
    0.214770004,
    0.283899993,
    0.328500003,
    0.348280013,
    0.348060012,
    0.336199999,
    0.318699986,
    0.290800005,
    0.251100004,
    0.195360005,
    0.142100006,
    0.0956400037,
    0.0579500087,
    0.0320100002,
    0.0147000002,
    0.00490000006,
    0.00240000011,
    0.00930000003,
    0.0291000009,
    0.0632700026,
    0.1096,
    0.1655,
    0.225749895,
    0.290399998,
    0.359699994,
    0.433449894,
    0.512050092,
    0.594500005,
    0.67839998,
    0.762099981,
    0.842499971,
    0.916299999,
    0.978600025,
    1.02629995,
    1.05669999,
    1.06219995,
    1.04560006,
    1.00259995,
    0.938399971,
    0.854449928,
    0.751399994,
    0.642400026,
    0.541899979,
    0.447899997,
    0.360799998,
    0.283499986,
    0.218700007,
    0.164900005,
    0.121200003,
    0.0873999968,
    0.0636000037,
    0.046769999,
    0.0329000019,
    0.0227000006,
    0.0158399995,
    0.0113591598,
    0.00811091624,
    0.00579034584,
    0.00410945714,
    0.00289932708,
    0.00204918999,
    0.00143997103,
    0.00099994929,
    0.000690078596,
    0.000476021291,
    0.000332301104,
    0.000234826104,
    0.000166150494,
    0.000117413001,
    8.30752688e-05,
    5.87065188e-05,
    4.15099385e-05,
    2.93532594e-05,
    2.06738296e-05,
    1.45597696e-05,
    1.02539798e-05,
    7.22145614e-06,
    5.085868e-06,
    3.58165198e-06,
    2.52252494e-06,
    1.77650895e-06,
    1.25114104e-06,
];
/// CIE 1931 ȳ at 360, 365, …, 830 nm.
const CIE_Y: [f64; 95] = [
    3.91699996e-06,
    6.96500001e-06,
    1.23899999e-05,
    2.202e-05,
    3.89999987e-05,
    6.39999998e-05,
    0.000119999997,
    0.000216999993,
    0.000395999989,
    0.000639999984,
    0.00121000002,
    0.00218000007,
    0.00400000019,
    0.00730000017,
    0.0115999999,
    0.0168399997,
    0.023,
    0.0297999997,
    0.0379999988,
    0.0480000004,
    0.0599999987,
    0.0738999993,
    0.0909800008,
    0.112599999,
    0.139019996,
    0.169300005,
    0.208020002,
    0.258599997,
    0.323000014,
    0.407299995,
    0.503000021,
    0.608200014,
    0.709999979,
    0.793200016,
    0.861999989,
    0.914850116,
    0.953999996,
    0.980300009,
    0.994950116,
    1.0,
    0.995000005,
    0.978600025,
    0.952000022,
    0.915400028,
    0.870000005,
    0.816299975,
    0.757000029,
    0.694899976,
    0.630999982,
    0.566799998,
    0.503000021,
    0.441199988,
    0.381000012,
    0.32100001,
    0.264999986,
    0.216999993,
    0.174999997,
    0.1382,
    0.107000001,
    0.0816000029,
    0.0610000007,
    0.0445800014,
    0.0320000015,
    0.0231999997,
    0.0170000009,
    0.0119200004,
    0.00820999965,
    0.00572300004,
    0.00410200004,
    0.00292899995,
    0.00209100009,
    0.00148400001,
    0.00104700006,
    0.000739999989,
    0.000520000001,
    0.000361100014,
    0.000249200006,
    0.000171899999,
    0.000119999997,
    8.47999981e-05,
    5.99999985e-05,
    4.23999991e-05,
    2.99999992e-05,
    2.11999995e-05,
    1.49899997e-05,
    1.05999998e-05,
    7.46570004e-06,
    5.25779978e-06,
    3.7028999e-06,
    2.60780007e-06,
    1.83659995e-06,
    1.29340003e-06,
    9.10929998e-07,
    6.41529994e-07,
    4.51809996e-07,
];
/// CIE 1931 z̄ at 360, 365, …, 830 nm.
const CIE_Z: [f64; 95] = [
    0.000606100017,
    0.001086,
    0.00194600003,
    0.003486,
    0.00645000115,
    0.0105499905,
    0.0200500097,
    0.0362100005,
    0.0678500086,
    0.110200003,
    0.207399994,
    0.371300012,
    0.645600021,
    1.0390501,
    1.38559997,
    1.62295997,
    1.74705994,
    1.78260005,
    1.77210999,
    1.74409997,
    1.66919994,
    1.52810001,
    1.28763998,
    1.04190004,
    0.812950075,
    0.61619997,
    0.46518001,
    0.353300005,
    0.272000015,
    0.212300003,
    0.158199996,
    0.111699998,
    0.0782499909,
    0.0572500117,
    0.0421600007,
    0.02984,
    0.0203000009,
    0.0133999996,
    0.00874999911,
    0.00574999908,
    0.00389999989,
    0.00274999905,
    0.00209999993,
    0.00179999997,
    0.00165000104,
    0.00139999995,
    0.00109999999,
    0.00100000005,
    0.00079999998,
    0.000600000028,
    0.000339999999,
    0.000239999994,
    0.000190000006,
    9.99999975e-05,
    4.99999915e-05,
    2.99999992e-05,
    1.99999995e-05,
    9.99999975e-06,
    0.0,
    0.0,
    0.0,
    0.0,
    0.0,
    0.0,
    0.0,
    0.0,
    0.0,
    0.0,
    0.0,
    0.0,
    0.0,
    0.0,
    0.0,
    0.0,
    0.0,
    0.0,
    0.0,
    0.0,
    0.0,
    0.0,
    0.0,
    0.0,
    0.0,
    0.0,
    0.0,
    0.0,
    0.0,
    0.0,
    0.0,
    0.0,
    0.0,
    0.0,
    0.0,
    0.0,
    0.0,
];
/// CIE D65 relative spectral power at 360, 365, …, 830 nm (100 at 560 nm).
const D65: [f64; 95] = [
    46.6383, 49.3637, 52.0891, 51.0323, 49.9755, 52.3118, 54.6482, 68.7015, 82.7549, 87.1204,
    91.486, 92.4589, 93.4318, 90.057, 86.6823, 95.7736, 104.865, 110.936, 117.008, 117.41, 117.812,
    116.336, 114.861, 115.392, 115.923, 112.367, 108.811, 109.082, 109.354, 108.578, 107.802,
    106.296, 104.79, 106.239, 107.689, 106.047, 104.405, 104.225, 104.046, 102.023, 100.0, 98.1671,
    96.3342, 96.0611, 95.788, 92.2368, 88.6856, 89.3459, 90.0062, 89.8026, 89.5991, 88.6489,
    87.6987, 85.4936, 83.2886, 83.4939, 83.6992, 81.863, 80.0268, 80.1207, 80.2146, 81.2462,
    82.2778, 80.281, 78.2842, 74.0027, 69.7213, 70.6652, 71.6091, 72.979, 74.349, 67.9765, 61.604,
    65.7448, 69.8856, 72.4863, 75.087, 69.3398, 63.5927, 55.0054, 46.4182, 56.6118, 66.8054,
    65.0941, 63.3828, 63.8434, 64.304, 61.8779, 59.4519, 55.7054, 51.959, 54.6998, 57.4406,
    58.8765, 60.3125,
];

/// What a spectrum describes: it decides the D65 weighting and the clamping.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum SpectrumUse {
    /// A reflectance (weighted by D65, clamped to [0, 1]).
    Reflectance,
    /// Emitted radiance or intensity (not weighted, clamped to ≥ 0).
    Emission,
    /// A real or imaginary index of refraction given as a spectrum. Mitsuba weights it by D65
    /// like any non-emitter property, but does not clamp it to 1 (clamped to ≥ 0).
    Ior,
}

/// Linear interpolation in a 95-entry table at wavelength `w` (zero outside [360, 830]).
fn table(t: &[f64; 95], w: f64) -> f64 {
    if !(CIE_MIN..=CIE_MAX).contains(&w) {
        return 0.0;
    }
    let x = (w - CIE_MIN) * 94.0 / (CIE_MAX - CIE_MIN);
    #[allow(clippy::cast_possible_truncation, clippy::cast_sign_loss)]
    let i0 = (x as usize).min(93);
    let f = x - i0 as f64;
    (1.0 - f) * t[i0] + f * t[i0 + 1]
}

/// XYZ to linear sRGB (Rec.709 primaries, D65 white), Mitsuba's `xyz_to_srgb`.
pub(crate) fn xyz_to_srgb(xyz: DVec3) -> DVec3 {
    DVec3::new(
        3.240_479 * xyz.x - 1.537_150 * xyz.y - 0.498_535 * xyz.z,
        -0.969_256 * xyz.x + 1.875_991 * xyz.y + 0.041_556 * xyz.z,
        0.055_648 * xyz.x - 0.204_043 * xyz.y + 1.057_311 * xyz.z,
    )
}

/// A piecewise-linear spectrum (wavelengths in nm, increasing) as linear Rec.709 RGB.
/// `None` if the lists are empty, of different lengths, not increasing or not finite.
pub(crate) fn spectrum_to_rgb(
    wavelengths: &[f64],
    values: &[f64],
    usage: SpectrumUse,
) -> Option<Rgb> {
    if wavelengths.is_empty()
        || wavelengths.len() != values.len()
        || wavelengths.windows(2).any(|w| w[1] <= w[0])
        || wavelengths.iter().chain(values).any(|v| !v.is_finite())
    {
        return None;
    }
    if wavelengths.len() == 1 {
        // A single sample is a constant spectrum.
        return Some(constant_spectrum_to_rgb(values[0], usage));
    }
    const STEPS: usize = 1000;
    let mut xyz = DVec3::ZERO;
    let (first, last) = (wavelengths[0], wavelengths[wavelengths.len() - 1]);
    for i in 0..STEPS {
        let w = CIE_MIN + (i as f64 / (STEPS - 1) as f64) * (CIE_MAX - CIE_MIN);
        if w < first || w > last {
            continue;
        }
        let j = wavelengths
            .partition_point(|&x| x <= w)
            .clamp(1, wavelengths.len() - 1)
            - 1;
        let (w0, w1, v0, v1) = (wavelengths[j], wavelengths[j + 1], values[j], values[j + 1]);
        let v = ((w - w1) * v0 + (w0 - w) * v1) / (w0 - w1);
        let d65 = if usage != SpectrumUse::Emission {
            table(&D65, w) / D65_NORMALIZATION
        } else {
            1.0
        };
        xyz += DVec3::new(table(&CIE_X, w), table(&CIE_Y, w), table(&CIE_Z, w)) * v * d65;
    }
    xyz *= (CIE_MAX - CIE_MIN) / CIE_Y_INTEGRAL / STEPS as f64;
    let rgb = xyz_to_srgb(xyz).max(DVec3::ZERO);
    let rgb = if usage == SpectrumUse::Reflectance {
        rgb.min(DVec3::ONE)
    } else {
        rgb
    };
    Some(rgb.as_vec3())
}

/// A constant spectrum of value `v`. Mitsuba's RGB variants give a constant *emission* the
/// colour of an equal-energy white in sRGB (`v · xyz_to_srgb(1, 1, 1)`, slightly purple), so
/// that they match its spectral variants; a constant reflectance or ior stays grey.
pub(crate) fn constant_spectrum_to_rgb(v: f64, usage: SpectrumUse) -> Rgb {
    match usage {
        SpectrumUse::Emission => (xyz_to_srgb(DVec3::ONE) * v).as_vec3(),
        SpectrumUse::Reflectance | SpectrumUse::Ior => Rgb::splat(v as f32),
    }
}

/// Reflectance of a conductor at normal incidence, per channel:
/// ((η − 1)² + k²) / ((η + 1)² + k²).
pub(crate) fn conductor_reflectance(eta: Rgb, k: Rgb) -> Rgb {
    let num = (eta - 1.0) * (eta - 1.0) + k * k;
    let den = (eta + 1.0) * (eta + 1.0) + k * k;
    (num / den.max(Rgb::splat(1e-12))).clamp(Rgb::ZERO, Rgb::ONE)
}

/// Reflectance at normal incidence of a conductor whose η and k are spectra, computed per
/// wavelength (on η's wavelengths, k interpolated linearly and held at its ends) and then
/// converted to RGB as a reflectance: closer to a spectral renderer than converting η and k
/// to RGB first. `None` if either spectrum is malformed.
pub(crate) fn conductor_reflectance_spectral(
    eta: (&[f64], &[f64]),
    k: (&[f64], &[f64]),
) -> Option<Rgb> {
    let (we, ve) = eta;
    let (wk, vk) = k;
    if we.is_empty() || wk.is_empty() || we.len() != ve.len() || wk.len() != vk.len() {
        return None;
    }
    let k_at = |w: f64| -> f64 {
        let j = wk.partition_point(|&x| x <= w);
        if j == 0 {
            vk[0]
        } else if j >= wk.len() {
            vk[wk.len() - 1]
        } else {
            let t = (w - wk[j - 1]) / (wk[j] - wk[j - 1]);
            (1.0 - t) * vk[j - 1] + t * vk[j]
        }
    };
    let r: Vec<f64> = we
        .iter()
        .zip(ve)
        .map(|(&w, &n)| {
            let k = k_at(w);
            ((n - 1.0) * (n - 1.0) + k * k) / ((n + 1.0) * (n + 1.0) + k * k)
        })
        .collect();
    spectrum_to_rgb(we, &r, SpectrumUse::Reflectance)
}

/// Reflectance of a smooth dielectric interface at normal incidence: ((η − 1) / (η + 1))².
pub(crate) fn dielectric_reflectance(eta: f32) -> f32 {
    let r = (eta - 1.0) / (eta + 1.0);
    r * r
}

/// Mitsuba's named conductors: (name, η RGB, k RGB), as its `scalar_rgb` variant reads them
/// (`mi.traverse(mi.load_dict({'type': 'conductor', 'material': name}))`, Mitsuba 3.9.1).
pub(crate) const METALS: &[(&str, [f32; 3], [f32; 3])] = &[
    (
        "a-C",
        [2.94405, 2.22714, 1.96816],
        [0.887465, 0.799299, 0.81529],
    ),
    (
        "Ag",
        [0.155276, 0.116728, 0.138388],
        [4.82835, 3.12222, 2.1469],
    ),
    ("Al", [1.6575, 0.880405, 0.521244], [9.22381, 6.2695, 4.837]),
    (
        "Au",
        [0.143036, 0.375307, 1.44205],
        [3.983, 2.38556, 1.60336],
    ),
    (
        "Be",
        [4.18501, 3.18503, 2.78406],
        [3.83547, 3.01012, 2.86899],
    ),
    ("Cr", [4.36967, 2.91651, 1.6549], [5.20655, 4.23131, 3.7547]),
    ("CsI", [2.1449, 1.70232, 1.66243], [0.0, 0.0, 0.0]),
    (
        "Cu",
        [0.201005, 0.92375, 1.10222],
        [3.91326, 2.45305, 2.14209],
    ),
    (
        "Cu2O",
        [3.55177, 2.94987, 2.75188],
        [0.114207, 0.193897, 0.606134],
    ),
    (
        "CuO",
        [3.24754, 2.44781, 2.21022],
        [0.52109, 0.570031, 0.722179],
    ),
    ("d-C", [2.70872, 2.31883, 2.2289], [0.0, 0.0, 0.0]),
    (
        "Hg",
        [2.39894, 1.44003, 0.90957],
        [6.32759, 4.37192, 3.42176],
    ),
    (
        "HgTe",
        [4.77904, 3.2312, 2.6599],
        [1.63161, 1.58081, 1.72929],
    ),
    (
        "Ir",
        [3.0863, 2.08219, 1.61791],
        [5.59215, 4.06709, 3.26731],
    ),
    (
        "K",
        [0.0640432, 0.0464098, 0.0381849],
        [2.1042, 1.34894, 0.913126],
    ),
    (
        "Li",
        [0.265791, 0.195618, 0.220949],
        [3.54015, 2.31112, 1.66861],
    ),
    (
        "Mo",
        [4.48397, 3.52513, 2.77631],
        [4.11144, 3.42083, 3.15061],
    ),
    (
        "Na_palik",
        [0.0602694, 0.0561409, 0.0619884],
        [3.17927, 2.11249, 1.57904],
    ),
    (
        "Nb",
        [3.42007, 2.79009, 2.39563],
        [3.44139, 2.73767, 2.57975],
    ),
    (
        "Ni_palik",
        [2.3673, 1.66337, 1.46708],
        [4.49881, 3.05015, 2.34544],
    ),
    (
        "Rh",
        [2.58579, 1.86022, 1.55426],
        [6.78226, 4.70299, 3.97607],
    ),
    (
        "Se",
        [4.05831, 2.84294, 2.82085],
        [0.75405, 0.638444, 0.521808],
    ),
    ("SnTe", [4.52425, 1.98164, 1.28159], [0.0, 0.0, 0.0]),
    (
        "Ta",
        [2.06272, 2.39294, 2.62793],
        [2.40836, 1.74149, 1.94703],
    ),
    (
        "Te",
        [7.39023, 4.4821, 2.63711],
        [3.25602, 3.52706, 3.29205],
    ),
    ("ThF4", [1.83071, 1.44223, 1.38765], [0.0, 0.0, 0.0]),
    (
        "TiC",
        [3.70053, 2.83742, 2.58229],
        [3.26564, 2.35159, 2.17279],
    ),
    (
        "TiN",
        [1.64845, 1.15052, 1.37982],
        [3.36833, 1.9435, 1.10207],
    ),
    (
        "VC",
        [3.65757, 2.75274, 2.53267],
        [3.0683, 2.19869, 1.96319],
    ),
    (
        "V_palik",
        [4.27758, 3.51295, 2.76107],
        [3.4913, 2.88945, 3.11152],
    ),
    (
        "VN",
        [2.8656, 2.11919, 1.94009],
        [3.03224, 2.05612, 1.61631],
    ),
    (
        "W",
        [4.37082, 3.30025, 2.99841],
        [3.50064, 2.60487, 2.27323],
    ),
];

/// η and k of a named conductor (Mitsuba names, e.g. `Au`, `Cu`, `Al`), if known.
pub(crate) fn metal(name: &str) -> Option<(Rgb, Rgb)> {
    METALS
        .iter()
        .find(|(n, _, _)| *n == name)
        .map(|(_, eta, k)| (Rgb::from_array(*eta), Rgb::from_array(*k)))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Mitsuba 3.9.1 (`scalar_rgb`) loads the shared spectral Cornell box's red wall
    /// reflectance and light radiance as these RGB values (read with `mi.traverse`).
    #[test]
    fn matches_mitsuba_rgb_mode() {
        let red_w: Vec<f64> = (0..76).map(|i| 400.0 + 4.0 * f64::from(i)).collect();
        let red_v = [
            0.04, 0.046, 0.048, 0.053, 0.049, 0.05, 0.053, 0.055, 0.057, 0.056, 0.059, 0.057,
            0.061, 0.061, 0.06, 0.062, 0.062, 0.062, 0.061, 0.062, 0.06, 0.059, 0.057, 0.058,
            0.058, 0.058, 0.056, 0.055, 0.056, 0.059, 0.057, 0.055, 0.059, 0.059, 0.058, 0.059,
            0.061, 0.061, 0.063, 0.063, 0.067, 0.068, 0.072, 0.08, 0.09, 0.099, 0.124, 0.154,
            0.192, 0.255, 0.287, 0.349, 0.402, 0.443, 0.487, 0.513, 0.558, 0.584, 0.62, 0.606,
            0.609, 0.651, 0.612, 0.61, 0.65, 0.638, 0.627, 0.62, 0.63, 0.628, 0.642, 0.639, 0.657,
            0.639, 0.635, 0.642,
        ];
        let red = spectrum_to_rgb(&red_w, &red_v, SpectrumUse::Reflectance).unwrap();
        let mitsuba = Rgb::new(0.49132, 0.049_228_1, 0.050_921_9);
        assert!(
            (red - mitsuba).abs().max_element() < 1e-4,
            "{red} vs {mitsuba}"
        );
        let light = spectrum_to_rgb(
            &[400.0, 500.0, 600.0, 700.0],
            &[0.0, 8.0, 15.6, 18.4],
            SpectrumUse::Emission,
        )
        .unwrap();
        let mitsuba = Rgb::new(20.7108, 10.8546, 2.77115);
        assert!(
            (light - mitsuba).abs().max_element() < 1e-3,
            "{light} vs {mitsuba}"
        );
    }

    #[test]
    fn conductor_reflectance_is_fresnel_at_normal_incidence() {
        // η = 1.5, k = 0: the dielectric value 0.04.
        let r = conductor_reflectance(Rgb::splat(1.5), Rgb::ZERO);
        assert!((r.x - 0.04).abs() < 1e-6);
        assert!((dielectric_reflectance(1.5) - 0.04).abs() < 1e-6);
        // Gold is reddish-yellow: red above blue.
        let (eta, k) = metal("Au").unwrap();
        let gold = conductor_reflectance(eta, k);
        assert!(gold.x > 0.9 && gold.z < 0.7, "{gold}");
    }
}
