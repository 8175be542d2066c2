//! How a glTF object plays its skinned animation, as a scene file writes it
//! (`animation: (clip: "walk", speed: 1, start: 0, stagger: 0.5, looping: true, playing: true)`).

use serde::Deserialize;

/// The animation an object's skinned meshes play. Every field has a default, so
/// `animation: ()` is the model's first clip from its start, looping, at normal speed.
#[derive(Clone, Debug, PartialEq, Deserialize)]
#[serde(rename = "Animation", deny_unknown_fields)]
pub struct AnimationDesc {
    /// Name of the glTF animation to play. Default: the model's first.
    #[serde(default)]
    pub clip: Option<String>,
    /// Clip seconds per second, finite (0 holds the start pose; negative plays backwards).
    /// Default 1.
    #[serde(default = "one")]
    pub speed: f32,
    /// Seconds into the clip at the first frame, finite and ≥ 0. Default 0.
    #[serde(default)]
    pub start: f32,
    /// Seconds added to `start` for each copy of a grid (copy *n* starts at
    /// `start + n · stagger`), so a crowd does not move in step; finite and ≥ 0. Default 0.
    #[serde(default)]
    pub stagger: f32,
    /// Whether the clip starts again past its end (else it holds its last pose). Default true.
    #[serde(default = "yes")]
    pub looping: bool,
    /// Whether the clip plays (else it holds the pose at `start`). Default true.
    #[serde(default = "yes")]
    pub playing: bool,
}

impl Default for AnimationDesc {
    fn default() -> Self {
        AnimationDesc {
            clip: None,
            speed: 1.0,
            start: 0.0,
            stagger: 0.0,
            looping: true,
            playing: true,
        }
    }
}

impl AnimationDesc {
    /// The time copy `n` of a grid starts at, seconds (before wrapping into the clip).
    pub fn start_of_copy(&self, n: u64) -> f32 {
        self.start + self.stagger * n as f32
    }

    /// Each out-of-range field: `(field, expected, found)`.
    pub(crate) fn problems(&self) -> Vec<(&'static str, &'static str, f32)> {
        let mut found = Vec::new();
        if !self.speed.is_finite() {
            found.push(("speed", "a finite number of clip seconds per second", self.speed));
        }
        for (field, value) in [("start", self.start), ("stagger", self.stagger)] {
            if !(value.is_finite() && value >= 0.0) {
                found.push((field, "finite seconds ≥ 0", value));
            }
        }
        found
    }
}

fn one() -> f32 {
    1.0
}

fn yes() -> bool {
    true
}

#[cfg(test)]
mod tests {
    use super::AnimationDesc;

    #[test]
    fn an_empty_animation_is_the_default() {
        let parsed: AnimationDesc = ron::from_str("()").expect("parses");
        assert_eq!(parsed, AnimationDesc::default());
    }

    #[test]
    fn copies_start_staggered() {
        let a = AnimationDesc {
            start: 1.0,
            stagger: 0.25,
            ..AnimationDesc::default()
        };
        assert_eq!(a.start_of_copy(0), 1.0);
        assert_eq!(a.start_of_copy(4), 2.0);
    }

    #[test]
    fn non_finite_and_negative_times_are_problems() {
        let a = AnimationDesc {
            speed: f32::NAN,
            start: -1.0,
            stagger: f32::INFINITY,
            ..AnimationDesc::default()
        };
        let fields: Vec<_> = a.problems().into_iter().map(|p| p.0).collect();
        assert_eq!(fields, ["speed", "start", "stagger"]);
    }
}
