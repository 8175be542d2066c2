//! The values some options of the `penumbra` command take, as clap parses them.

use clap::ValueEnum;

use penumbra::settings::CascadeFit;

/// A shadow filter (`ShadowMode`).
#[derive(Clone, Copy, ValueEnum)]
pub enum Mode {
    Pcf,
    Pcss,
    Vsm,
    Evsm,
    Evsm4,
    Msm,
}

/// How a sun's cascades are fitted (`CascadeFit`).
#[derive(Clone, Copy, ValueEnum)]
pub enum Fit {
    Tight,
    Stable,
    DepthBounds,
}

impl From<Fit> for CascadeFit {
    fn from(fit: Fit) -> Self {
        match fit {
            Fit::Tight => CascadeFit::Tight,
            Fit::Stable => CascadeFit::Stable,
            Fit::DepthBounds => CascadeFit::DepthBounds,
        }
    }
}

/// How a sun's shadow is divided into maps (`SunLayout`).
#[derive(Clone, Copy, PartialEq, Eq, ValueEnum)]
pub enum Layout {
    Cascades,
    Clipmap,
    VirtualClipmap,
}

/// Storage of a sun's moments (`MomentFormat`).
#[derive(Clone, Copy, ValueEnum)]
pub enum Precision {
    Auto,
    Fp16,
    Fp32,
}

/// PCSS quality (`PcssQuality`).
#[derive(Clone, Copy, ValueEnum)]
pub enum Quality {
    Low,
    Medium,
    High,
}

/// Deferred lighting of the prepass's pixels (`DeferredLighting`).
#[derive(Clone, Copy, PartialEq, Eq, ValueEnum)]
pub enum Deferred {
    Auto,
    On,
    Off,
}

/// The depth prepass (`DepthPrepass`).
#[derive(Clone, Copy, PartialEq, Eq, ValueEnum)]
pub enum Prepass {
    Auto,
    On,
    Off,
}
