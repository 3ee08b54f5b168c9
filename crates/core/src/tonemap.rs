//! How the viewer maps radiance to the display: the tone mappers both display paths offer
//! (`display.wgsl` on an adapter, its CPU twin for the CPU backend).

/// How radiance is mapped to the display's [0, 1]; the discriminants are the display
/// shader's `TONEMAP_*`.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum ToneMap {
    /// Clamped: what `pathlight render` writes to PNG.
    #[default]
    Clamp = 0,
    /// The ACES filmic curve (Narkowicz's fit).
    Aces = 1,
    /// AgX with its default look.
    Agx = 2,
}

impl ToneMap {
    /// The next tone mapper in the cycle (the viewer's `T` key).
    pub fn next(self) -> Self {
        match self {
            ToneMap::Clamp => ToneMap::Aces,
            ToneMap::Aces => ToneMap::Agx,
            ToneMap::Agx => ToneMap::Clamp,
        }
    }

    /// Its name, for messages and the title.
    pub fn name(self) -> &'static str {
        match self {
            ToneMap::Clamp => "clamp",
            ToneMap::Aces => "ACES",
            ToneMap::Agx => "AgX",
        }
    }
}
