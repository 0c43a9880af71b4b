//! Indices of refraction that depend on wavelength: Sellmeier and Cauchy laws, tabulated
//! measurements, and the named glasses of pbrt-v4.

use super::SpectrumError;
use super::spectra::PiecewiseLinear;

/// The Sellmeier law n²(λ) = 1 + Σᵢ Bᵢ λ² / (λ² − Cᵢ), λ in µm, Cᵢ in µm².
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Sellmeier {
    b: [f64; 3],
    c: [f64; 3],
}

impl Sellmeier {
    /// Schott N-BK7 (Schott's catalogue, as refractiveindex.info lists it).
    pub const SCHOTT_N_BK7: Self = Self {
        b: [1.039_612_12, 0.231_792_344, 1.010_469_45],
        c: [0.006_000_698_67, 0.020_017_914_4, 103.560_653],
    };
    /// Fused silica (Malitson 1965: B = 0.6961663, 0.4079426, 0.8974794; the resonances at
    /// 0.0684043, 0.1162414 and 9.896161 µm, squared here).
    pub const FUSED_SILICA: Self = Self {
        b: [0.696_166_3, 0.407_942_6, 0.897_479_4],
        c: [
            0.068_404_3 * 0.068_404_3,
            0.116_241_4 * 0.116_241_4,
            9.896_161 * 9.896_161,
        ],
    };

    /// The law of coefficients `b` and `c` (µm²). Refused: a non-finite coefficient, or an
    /// index of refraction below 1 or not finite anywhere in 360–830 nm (a resonance Cᵢ inside
    /// the range is a pole there).
    pub fn new(b: [f64; 3], c: [f64; 3]) -> Result<Self, SpectrumError> {
        const NAMES: [&str; 6] = ["B1", "B2", "B3", "C1", "C2", "C3"];
        for (name, value) in NAMES.into_iter().zip(b.into_iter().chain(c)) {
            if !value.is_finite() {
                return Err(SpectrumError::NonFiniteCoefficient { name, value });
            }
        }
        let law = Self { b, c };
        // A pole: n² changes sign across λ² = Cᵢ, so it is below 1 on one side.
        for &ci in &c {
            if (0.36 * 0.36..=0.83 * 0.83).contains(&ci) {
                let wavelength = ci.sqrt() * 1000.0;
                return Err(SpectrumError::IorOutOfRange {
                    wavelength,
                    ior: f64::INFINITY,
                });
            }
        }
        check_range(|l| law.ior(l))?;
        Ok(law)
    }

    /// The coefficients B₁, B₂, B₃ and C₁, C₂, C₃ (µm²).
    pub fn coefficients(&self) -> ([f64; 3], [f64; 3]) {
        (self.b, self.c)
    }

    /// The index of refraction at `lambda` nm (NaN where n² < 0, which `new` refuses in range).
    pub fn ior(&self, lambda: f64) -> f64 {
        let l2 = (lambda * 1e-3) * (lambda * 1e-3);
        let n2 = 1.0
            + self
                .b
                .iter()
                .zip(&self.c)
                .map(|(b, c)| b * l2 / (l2 - c))
                .sum::<f64>();
        n2.sqrt()
    }
}

/// Cauchy's law n(λ) = A + B / λ² + C / λ⁴, λ in µm.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Cauchy {
    a: f64,
    b: f64,
    c: f64,
}

impl Cauchy {
    /// The law of coefficients `a`, `b` (µm²) and `c` (µm⁴). Refused: a non-finite coefficient or
    /// an index of refraction below 1 anywhere in 360–830 nm.
    pub fn new(a: f64, b: f64, c: f64) -> Result<Self, SpectrumError> {
        for (name, value) in [("A", a), ("B", b), ("C", c)] {
            if !value.is_finite() {
                return Err(SpectrumError::NonFiniteCoefficient { name, value });
            }
        }
        let law = Self { a, b, c };
        check_range(|l| law.ior(l))?;
        Ok(law)
    }

    /// The coefficients a, b (µm²) and c (µm⁴).
    pub fn coefficients(&self) -> [f64; 3] {
        [self.a, self.b, self.c]
    }

    /// The index of refraction at `lambda` nm.
    pub fn ior(&self, lambda: f64) -> f64 {
        let inv2 = 1.0 / ((lambda * 1e-3) * (lambda * 1e-3));
        self.a + self.b * inv2 + self.c * inv2 * inv2
    }
}

/// Checks an index of refraction at every 0.5 nm of 360–830 nm: finite and at least 1.
fn check_range(ior: impl Fn(f64) -> f64) -> Result<(), SpectrumError> {
    for i in 0..=940 {
        let wavelength = 360.0 + 0.5 * f64::from(i);
        let n = ior(wavelength);
        if !(n.is_finite() && n >= 1.0) {
            return Err(SpectrumError::IorOutOfRange { wavelength, ior: n });
        }
    }
    Ok(())
}

/// An index of refraction as a function of wavelength.
#[derive(Clone, Debug, PartialEq)]
pub enum Ior {
    /// No dispersion.
    Constant(f64),
    /// Sellmeier's law.
    Sellmeier(Sellmeier),
    /// Cauchy's law.
    Cauchy(Cauchy),
    /// Measured values, linear between them (held at the ends for the named glasses).
    Tabulated(PiecewiseLinear),
}

impl Ior {
    /// A constant index of refraction, finite and at least 1.
    pub fn constant(n: f64) -> Result<Self, SpectrumError> {
        if n.is_finite() && n >= 1.0 {
            Ok(Self::Constant(n))
        } else {
            Err(SpectrumError::IorOutOfRange {
                wavelength: 360.0,
                ior: n,
            })
        }
    }

    /// A measured index of refraction: a valid [`PiecewiseLinear`] that is at least 1 over
    /// 360–830 nm (so it must cover the range).
    pub fn tabulated(spectrum: PiecewiseLinear) -> Result<Self, SpectrumError> {
        check_range(|l| spectrum.eval(l))?;
        Ok(Self::Tabulated(spectrum))
    }

    /// A glass by its pbrt-v4 name (`glass-BK7`, `glass-BAF10`, `glass-FK51A`, `glass-LASF9`,
    /// `glass-F5` or `glass-SF5`, `glass-F10` or `glass-SF10`, `glass-F11` or `glass-SF11`:
    /// pbrt-v4's tables) or `glass-fused-silica` (Malitson's Sellmeier law; pbrt-v4 has none).
    pub fn named(name: &str) -> Option<Self> {
        let table: &[f64] = match name {
            "glass-BK7" => &GLASS_BK7,
            "glass-BAF10" => &GLASS_BAF10,
            "glass-FK51A" => &GLASS_FK51A,
            "glass-LASF9" => &GLASS_LASF9,
            "glass-F5" | "glass-SF5" => &GLASS_SF5,
            "glass-F10" | "glass-SF10" => &GLASS_SF10,
            "glass-F11" | "glass-SF11" => &GLASS_SF11,
            "glass-fused-silica" => return Some(Self::Sellmeier(Sellmeier::FUSED_SILICA)),
            _ => return None,
        };
        Some(Self::Tabulated(PiecewiseLinear::from_interleaved(table)))
    }

    /// The names [`Ior::named`] knows.
    pub const NAMES: [&str; 11] = [
        "glass-BK7",
        "glass-BAF10",
        "glass-FK51A",
        "glass-LASF9",
        "glass-F5",
        "glass-SF5",
        "glass-F10",
        "glass-SF10",
        "glass-F11",
        "glass-SF11",
        "glass-fused-silica",
    ];

    /// The index of refraction at `lambda` nm.
    pub fn eval(&self, lambda: f64) -> f64 {
        match self {
            Self::Constant(n) => *n,
            Self::Sellmeier(s) => s.ior(lambda),
            Self::Cauchy(c) => c.ior(lambda),
            Self::Tabulated(t) => t.eval(lambda),
        }
    }

    /// Whether it varies with wavelength, so that a refraction must terminate the companion
    /// wavelengths ([`super::SampledWavelengths::terminate_secondary`]).
    pub fn is_dispersive(&self) -> bool {
        !matches!(self, Self::Constant(_))
    }
}

/// Schott BK7 η, interleaved (nm, value) (pbrt-v4 `GlassBK7_eta`, from refractiveindex.info, CC0).
#[rustfmt::skip]
pub(super) const GLASS_BK7: [f64; 58] = [
    300.0, 1.5527702635739, 322.0, 1.5458699289209, 344.0, 1.5404466868331,
    366.0, 1.536090527917, 388.0, 1.53252773217, 410.0, 1.529568767224,
    432.0, 1.5270784291406, 454.0, 1.5249578457324, 476.0, 1.5231331738499,
    498.0, 1.5215482528369, 520.0, 1.5201596882463, 542.0, 1.5189334783109,
    564.0, 1.5178426478869, 586.0, 1.516865556749, 608.0, 1.5159846691816,
    630.0, 1.5151856452759, 652.0, 1.5144566604975, 674.0, 1.513787889767,
    696.0, 1.5131711117948, 718.0, 1.5125994024544, 740.0, 1.5120668948646,
    762.0, 1.5115685899969, 784.0, 1.5111002059336, 806.0, 1.5106580569705,
    828.0, 1.5102389559626, 850.0, 1.5098401349174, 872.0, 1.5094591800239,
    894.0, 1.5090939781792, 916.0, 1.5087426727363,
];

/// Schott BAF10 η, interleaved (nm, value) (pbrt-v4 `GlassBAF10_eta`, from refractiveindex.info, CC0).
#[rustfmt::skip]
pub(super) const GLASS_BAF10: [f64; 54] = [
    350.0, 1.7126880848268, 371.0, 1.7044510025682, 393.0, 1.6978539633931,
    414.0, 1.6924597573902, 436.0, 1.6879747521657, 457.0, 1.6841935148947,
    479.0, 1.6809676313681, 500.0, 1.6781870617363, 522.0, 1.6757684467878,
    543.0, 1.6736474831891, 565.0, 1.6717737892968, 586.0, 1.6701073530462,
    608.0, 1.6686160168249, 629.0, 1.6672736605352, 651.0, 1.6660588657981,
    672.0, 1.6649539185393, 694.0, 1.6639440538738, 715.0, 1.6630168772865,
    737.0, 1.6621619159417, 758.0, 1.6613702672977, 780.0, 1.6606343213443,
    801.0, 1.6599475391478, 823.0, 1.6593042748862, 844.0, 1.6586996317841,
    866.0, 1.6581293446924, 887.0, 1.6575896837763, 909.0, 1.6570773750475,
];

/// Schott FK51A η, interleaved (nm, value) (pbrt-v4 `GlassFK51A_eta`, from refractiveindex.info, CC0).
#[rustfmt::skip]
pub(super) const GLASS_FK51A: [f64; 58] = [
    290.0, 1.5145777204082, 312.0, 1.5092112868865, 334.0, 1.5049961987453,
    356.0, 1.5016153970446, 378.0, 1.4988558885761, 400.0, 1.496569610433,
    422.0, 1.4946506898002, 444.0, 1.4930216011953, 466.0, 1.4916244098644,
    488.0, 1.49041505042, 511.0, 1.4893594837084, 533.0, 1.4884310526027,
    555.0, 1.4876086240083, 577.0, 1.486875258765, 599.0, 1.486217243501,
    621.0, 1.4856233753353, 643.0, 1.4850844262039, 665.0, 1.4845927367446,
    687.0, 1.484141904927, 709.0, 1.483726544853, 732.0, 1.4833420981287,
    754.0, 1.4829846850495, 776.0, 1.482650986233, 798.0, 1.4823381477539,
    820.0, 1.4820437045732, 842.0, 1.4817655183243, 864.0, 1.481501726448,
    886.0, 1.4812507003621, 908.0, 1.4810110108734,
];

/// Schott LASF9 η, interleaved (nm, value) (pbrt-v4 `GlassLASF9_eta`, from refractiveindex.info, CC0).
#[rustfmt::skip]
pub(super) const GLASS_LASF9: [f64; 52] = [
    370.0, 1.9199725545705, 391.0, 1.9057858245373, 412.0, 1.8945401582481,
    433.0, 1.8854121949451, 455.0, 1.877863643024, 476.0, 1.8715257028176,
    497.0, 1.8661362648008, 519.0, 1.8615034773283, 540.0, 1.8574834752011,
    561.0, 1.8539661699122, 583.0, 1.8508658556, 604.0, 1.8481148099285,
    625.0, 1.8456588222442, 646.0, 1.8434539988324, 668.0, 1.8414644361915,
    689.0, 1.8396604975285, 710.0, 1.8380175167434, 732.0, 1.8365148106821,
    753.0, 1.8351349171703, 774.0, 1.8338630007484, 796.0, 1.8326863845545,
    817.0, 1.8315941782006, 838.0, 1.8305769794709, 859.0, 1.8296266333424,
    881.0, 1.8287360359155, 902.0, 1.8278989738228,
];

/// Schott SF5 η, interleaved (nm, value) (pbrt-v4 `GlassSF5_eta`, from refractiveindex.info, CC0).
#[rustfmt::skip]
pub(super) const GLASS_SF5: [f64; 52] = [
    370.0, 1.7286549847245, 391.0, 1.7170151864402, 412.0, 1.7079037179421,
    433.0, 1.7005724270177, 455.0, 1.6945472844297, 476.0, 1.6895110487297,
    497.0, 1.685242265691, 519.0, 1.6815810964, 540.0, 1.678409006027,
    561.0, 1.6756360973958, 583.0, 1.6731928929908, 604.0, 1.6710248234743,
    625.0, 1.6690884260039, 646.0, 1.6673486579281, 668.0, 1.6657769585173,
    689.0, 1.6643498246044, 710.0, 1.6630477468358, 732.0, 1.6618544037398,
    753.0, 1.6607560432197, 774.0, 1.6597410023473, 796.0, 1.6587993305922,
    817.0, 1.6579224913632, 838.0, 1.6571031234995, 859.0, 1.6563348491305,
    881.0, 1.6556121177295, 902.0, 1.654930078671,
];

/// Schott SF10 η, interleaved (nm, value) (pbrt-v4 `GlassSF10_eta`, from refractiveindex.info, CC0).
#[rustfmt::skip]
pub(super) const GLASS_SF10: [f64; 52] = [
    380.0, 1.7905788948419, 401.0, 1.7776074571692, 422.0, 1.7673620572474,
    443.0, 1.7590649148507, 464.0, 1.7522127524444, 486.0, 1.7464635698826,
    507.0, 1.741575877046, 528.0, 1.7373738218659, 549.0, 1.7337260730259,
    570.0, 1.7305324562829, 592.0, 1.7277151818026, 613.0, 1.7252129043714,
    634.0, 1.7229765939984, 655.0, 1.7209665988467, 676.0, 1.719150514229,
    698.0, 1.7175016091415, 719.0, 1.7159976462946, 740.0, 1.7146199848831,
    761.0, 1.7133528897994, 782.0, 1.7121829937648, 804.0, 1.7110988742233,
    825.0, 1.7100907173852, 846.0, 1.7091500491754, 867.0, 1.7082695180523,
    888.0, 1.7074427184169, 910.0, 1.7066640460471,
];

/// Schott SF11 η, interleaved (nm, value) (pbrt-v4 `GlassSF11_eta`, from refractiveindex.info, CC0).
#[rustfmt::skip]
pub(super) const GLASS_SF11: [f64; 52] = [
    370.0, 1.8700216173234, 391.0, 1.8516255860581, 412.0, 1.8374707714715,
    433.0, 1.8262323798466, 455.0, 1.8170946940119, 476.0, 1.8095242343848,
    497.0, 1.803155581666, 519.0, 1.7977291183308, 540.0, 1.7930548640505,
    561.0, 1.7889903663666, 583.0, 1.7854266026774, 604.0, 1.7822786683156,
    625.0, 1.7794794394722, 646.0, 1.7769751487395, 668.0, 1.7747222267051,
    689.0, 1.7726850031375, 710.0, 1.770834004936, 732.0, 1.7691446766161,
    753.0, 1.7675964052635, 774.0, 1.7661717683505, 796.0, 1.764855947008,
    817.0, 1.7636362637211, 838.0, 1.7625018146862, 859.0, 1.7614431749629,
    881.0, 1.7604521601554, 902.0, 1.7595216323879,
];

#[cfg(test)]
mod tests {
    use super::*;

    /// Schott's catalogue: N-BK7 has n_d = 1.5168 at the helium d line, 587.56 nm; n_F = 1.52238
    /// at 486.13 nm and n_C = 1.51432 at 656.27 nm.
    #[test]
    fn bk7_matches_schott() {
        let table = Ior::named("glass-BK7").unwrap();
        let law = Ior::Sellmeier(Sellmeier::SCHOTT_N_BK7);
        for ior in [&table, &law] {
            assert!(
                (ior.eval(587.56) - 1.5168).abs() < 1e-4,
                "{}",
                ior.eval(587.56)
            );
            assert!(
                (ior.eval(486.13) - 1.52238).abs() < 2e-4,
                "{}",
                ior.eval(486.13)
            );
            assert!(
                (ior.eval(656.27) - 1.51432).abs() < 2e-4,
                "{}",
                ior.eval(656.27)
            );
        }
    }

    /// Malitson's fused silica: n = 1.4585 at 587.6 nm.
    #[test]
    fn fused_silica_matches_malitson() {
        let n = Ior::named("glass-fused-silica").unwrap().eval(587.6);
        assert!((n - 1.4585).abs() < 1e-4, "{n}");
    }

    /// Every named glass covers 360–830 nm, is normally dispersive there (n falls as λ grows)
    /// and lies between 1.4 and 2.
    #[test]
    fn named_glasses_are_valid_and_normally_dispersive() {
        for name in Ior::NAMES {
            let ior = Ior::named(name).unwrap();
            assert!(ior.is_dispersive());
            let n = |l: f64| ior.eval(l);
            assert!(
                Ior::tabulated(
                    PiecewiseLinear::new(
                        (360..=830).map(f64::from).collect(),
                        (360..=830).map(|l| n(f64::from(l))).collect()
                    )
                    .unwrap()
                )
                .is_ok()
            );
            for l in 360..830 {
                let l = f64::from(l);
                assert!((1.4..2.0).contains(&n(l)), "{name} at {l}: {}", n(l));
                assert!(n(l + 1.0) <= n(l) + 1e-12, "{name} rises at {l}");
            }
        }
        assert!(Ior::named("glass-unobtainium").is_none());
    }

    #[test]
    fn laws_that_fall_below_one_are_refused() {
        // A Cauchy law of A = 0.9 is below 1 at the red end.
        assert!(matches!(
            Cauchy::new(0.9, 0.01, 0.0),
            Err(SpectrumError::IorOutOfRange { .. })
        ));
        let ok = Cauchy::new(1.5, 0.004, 0.0).unwrap();
        // 1.5 + 0.004 / 0.5² = 1.516 at 500 nm.
        assert!((ok.ior(500.0) - 1.516).abs() < 1e-12);
        assert!(matches!(
            Cauchy::new(f64::NAN, 0.0, 0.0),
            Err(SpectrumError::NonFiniteCoefficient { name: "A", .. })
        ));
        // A resonance at 500 nm (C = 0.25 µm²) is a pole inside the range.
        assert!(matches!(
            Sellmeier::new([1.0, 0.0, 0.0], [0.25, 0.0, 0.0]),
            Err(SpectrumError::IorOutOfRange { .. })
        ));
        // Negative strengths that pull n² below 1.
        assert!(matches!(
            Sellmeier::new([-0.5, 0.0, 0.0], [0.01, 0.0, 0.0]),
            Err(SpectrumError::IorOutOfRange { .. })
        ));
        assert!(matches!(
            Sellmeier::new([1.0, 0.0, 0.0], [f64::INFINITY, 0.0, 0.0]),
            Err(SpectrumError::NonFiniteCoefficient { name: "C1", .. })
        ));
        let bk7 = Sellmeier::new(
            [1.039_612_12, 0.231_792_344, 1.010_469_45],
            [0.006_000_698_67, 0.020_017_914_4, 103.560_653],
        )
        .unwrap();
        assert_eq!(bk7, Sellmeier::SCHOTT_N_BK7);
        assert!(Ior::constant(0.8).is_err() && Ior::constant(1.33).is_ok());
        // A measured list that does not cover the range is 0 outside it.
        let short = PiecewiseLinear::new(vec![400.0, 700.0], vec![1.5, 1.5]).unwrap();
        assert!(Ior::tabulated(short).is_err());
    }
}
