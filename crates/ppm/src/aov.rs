//! The auxiliary images a render can give besides the beauty image.

/// Auxiliary images ("arbitrary output variables") besides the beauty image.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Aov {
    /// Gather radius R per pixel (mean over the pixel's hitpoint slots); photon mappers only.
    Radius,
    /// Accumulated photon count N per pixel (mean over the slots); photon mappers only.
    PhotonCount,
    /// Frequency radius r_freq per pixel (mean over the slots that have one; 0 where no
    /// frequency photon arrived); frequency methods only.
    FreqRadius,
    /// Share of the pixel's slots whose radius is held by the frequency floor (R ≤ r_freq);
    /// frequency methods only.
    FreqHeld,
    /// Standard deviation of the Gaussian that pools the pixel's estimate with its neighbours'
    /// in scene units (mean over the slots; 0 where nothing is pooled); photon mappers only.
    PoolWidth,
    /// Albedo (reflectance) of the first surface seen through the pixel centre (RGB).
    Albedo,
    /// Shading normal of the first surface seen through the pixel centre, facing the camera
    /// (XYZ in [−1, 1]).
    Normal,
    /// Distance from the camera to the first surface seen through the pixel centre (0 if none).
    Depth,
}

impl Aov {
    /// Every AOV.
    pub const ALL: [Aov; 8] = [
        Aov::Radius,
        Aov::PhotonCount,
        Aov::FreqRadius,
        Aov::FreqHeld,
        Aov::PoolWidth,
        Aov::Albedo,
        Aov::Normal,
        Aov::Depth,
    ];

    /// Channel names of this AOV in an image file, e.g. `["albedo.R", "albedo.G", "albedo.B"]`.
    #[must_use]
    pub fn channel_names(self) -> &'static [&'static str] {
        match self {
            Aov::Radius => &["radius"],
            Aov::PhotonCount => &["count"],
            Aov::FreqRadius => &["freq.radius"],
            Aov::FreqHeld => &["freq.held"],
            Aov::PoolWidth => &["pool.width"],
            Aov::Albedo => &["albedo.R", "albedo.G", "albedo.B"],
            Aov::Normal => &["normal.X", "normal.Y", "normal.Z"],
            Aov::Depth => &["depth"],
        }
    }
}
