//! The scripted robustness run of `--exercise`: what the viewer does to itself at which
//! event-loop tick, so a headless test (under Xvfb) covers resizing, minimising to 0×0 and
//! back, a lost surface, and settings changes that recreate GPU resources.

/// One scripted action.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ExerciseStep {
    /// Ask the window system for a new inner size.
    Resize(u32, u32),
    /// Behave as if the window had been minimised (a 0×0 resize, as some platforms send).
    Minimise,
    /// Restore the size the window had before [`Minimise`](Self::Minimise).
    Restore,
    /// Treat the next frame's surface as lost (reconfigure and skip the frame).
    LoseSurface,
    /// Switch to PCSS, two cascades and a 1024² shadow map.
    ChangeSettings,
    /// Back to the settings the scene started with.
    ResetSettings,
}

/// The step to take at event-loop tick `tick`, if any.
pub fn exercise_step(tick: u32) -> Option<ExerciseStep> {
    match tick {
        3 => Some(ExerciseStep::Resize(480, 300)),
        6 => Some(ExerciseStep::Minimise),
        9 => Some(ExerciseStep::Restore),
        12 => Some(ExerciseStep::LoseSurface),
        15 => Some(ExerciseStep::ChangeSettings),
        18 => Some(ExerciseStep::ResetSettings),
        _ => None,
    }
}

/// The tick after which the script has nothing left to do.
pub const EXERCISE_TICKS: u32 = 21;

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_step_happens_once_before_the_end() {
        let steps: Vec<_> = (0..EXERCISE_TICKS).filter_map(exercise_step).collect();
        assert_eq!(steps.len(), 6);
        assert!(steps.contains(&ExerciseStep::Minimise) && steps.contains(&ExerciseStep::Restore));
        let minimise = steps.iter().position(|s| *s == ExerciseStep::Minimise);
        let restore = steps.iter().position(|s| *s == ExerciseStep::Restore);
        assert!(minimise < restore);
        assert!((EXERCISE_TICKS..EXERCISE_TICKS + 100).all(|t| exercise_step(t).is_none()));
    }
}
