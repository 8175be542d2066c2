//! Live reload: watches the open scene file (and an optional settings file) and applies an
//! edit within a poll interval. A scene edit is loaded and prepared completely before the old
//! scene is removed, so an invalid edit (bad RON, a missing texture, a broken model) leaves
//! the last good scene running and reports the error instead.

use std::path::{Path, PathBuf};
use std::time::{Duration, Instant};

use bevy_ecs::world::World;

use crate::app::{PreparedScene, despawn_scene};
use crate::ecs::components::DirectionalLight;
use crate::scene::{SceneDesc, load_settings};
use crate::settings::ShadowSettings;

/// How often the files are checked by default.
pub const DEFAULT_POLL_INTERVAL: Duration = Duration::from_millis(250);

/// What one [`LiveReload::poll`] did.
#[derive(Clone, Debug, PartialEq)]
pub enum ReloadOutcome {
    /// Nothing changed on disk (or the poll interval has not passed).
    Unchanged,
    /// An edit was applied.
    Applied {
        /// The scene was replaced (false when only the settings file changed).
        scene: bool,
        /// The scene's camera differs from the one before, so a free camera should reset.
        camera_changed: bool,
    },
    /// An edit was rejected; the previous scene and settings stay. The text is the error.
    Rejected(String),
}

/// A watched file: its path and the contents last seen.
#[derive(Debug)]
pub(crate) struct FileWatch {
    /// The file.
    pub path: PathBuf,
    seen: Option<Vec<u8>>,
}

impl FileWatch {
    /// Watches `path`, taking its current contents as seen.
    pub fn new(path: &Path) -> Self {
        Self {
            path: path.to_owned(),
            seen: std::fs::read(path).ok(),
        }
    }

    /// Watches `path` as if never read: the first [`changed`](Self::changed) reports it.
    #[cfg(feature = "viewer")]
    pub fn unread(path: &Path) -> Self {
        Self {
            path: path.to_owned(),
            seen: None,
        }
    }

    /// Reads the file and reports whether its contents differ from the last read.
    pub fn changed(&mut self) -> bool {
        // NOTE: contents, not modification times, are compared: editors that write twice in
        // one clock tick, and file systems with coarse timestamps, still count as an edit.
        let now = std::fs::read(&self.path).ok();
        if now == self.seen {
            return false;
        }
        self.seen = now;
        true
    }
}

/// Watches a scene file and an optional settings file and re-applies them on change.
#[derive(Debug)]
pub struct LiveReload {
    scene: FileWatch,
    settings: Option<FileWatch>,
    /// The scene that is running (the last one that loaded).
    current: SceneDesc,
    interval: Duration,
    last_poll: Option<Instant>,
    /// A scene edit not applied yet (it was rejected, or the settings file was).
    scene_pending: bool,
    /// The last rejected edit's error, cleared by the next good edit.
    pub error: Option<String>,
}

impl LiveReload {
    /// Starts watching `scene_path`, whose contents `current` were loaded from, and
    /// `settings_path` if given.
    pub fn new(scene_path: &Path, current: SceneDesc, settings_path: Option<&Path>) -> Self {
        Self {
            scene: FileWatch::new(scene_path),
            settings: settings_path.map(FileWatch::new),
            current,
            interval: DEFAULT_POLL_INTERVAL,
            last_poll: None,
            scene_pending: false,
            error: None,
        }
    }

    /// Changes how often [`poll`](Self::poll) looks at the files (zero: every call).
    pub fn with_interval(mut self, interval: Duration) -> Self {
        self.interval = interval;
        self
    }

    /// The scene that is running.
    pub fn current(&self) -> &SceneDesc {
        &self.current
    }

    /// The watched scene file.
    pub fn scene_path(&self) -> &Path {
        &self.scene.path
    }

    /// The watched settings file, if any.
    pub fn settings_path(&self) -> Option<&Path> {
        self.settings.as_ref().map(|w| w.path.as_path())
    }

    /// Checks the files (at most once per interval) and applies what changed.
    pub fn poll(&mut self, world: &mut World) -> ReloadOutcome {
        let now = Instant::now();
        if self.last_poll.is_some_and(|t| now - t < self.interval) {
            return ReloadOutcome::Unchanged;
        }
        self.last_poll = Some(now);
        let scene_changed = self.scene.changed();
        let settings_changed = self.settings.as_mut().is_some_and(FileWatch::changed);
        if !scene_changed && !settings_changed {
            return ReloadOutcome::Unchanged;
        }
        self.scene_pending |= scene_changed;
        let outcome = self.apply(world, self.scene_pending);
        if matches!(outcome, ReloadOutcome::Applied { .. }) {
            self.scene_pending = false;
        }
        self.error = match &outcome {
            ReloadOutcome::Rejected(e) => Some(e.clone()),
            _ => None,
        };
        outcome
    }

    /// Loads the settings file (if any) and, when `scene_changed`, the scene; replaces the
    /// world's scene only when everything loaded.
    fn apply(&mut self, world: &mut World, scene_changed: bool) -> ReloadOutcome {
        let settings = match self.settings_path().map(load_settings).transpose() {
            Ok(s) => s,
            Err(e) => return ReloadOutcome::Rejected(e.to_string()),
        };
        if !scene_changed {
            if let Some(settings) = settings {
                set_sun_settings(world, settings);
            }
            return ReloadOutcome::Applied {
                scene: false,
                camera_changed: false,
            };
        }
        let desc = match SceneDesc::load(&self.scene.path) {
            Ok(d) => d,
            Err(e) => return ReloadOutcome::Rejected(e.to_string()),
        };
        let prepared = match PreparedScene::new(&desc) {
            Ok(p) => p,
            Err(e) => return ReloadOutcome::Rejected(format!("{}: {e}", self.scene.path.display())),
        };
        despawn_scene(world);
        prepared.spawn(world);
        if let Some(settings) = settings {
            set_sun_settings(world, settings);
        }
        let camera_changed = desc.camera != self.current.camera;
        self.current = desc;
        ReloadOutcome::Applied {
            scene: true,
            camera_changed,
        }
    }
}

/// Puts `settings` on every directional light.
pub fn set_sun_settings(world: &mut World, settings: ShadowSettings) {
    let mut lights = world.query::<(&DirectionalLight, &mut ShadowSettings)>();
    for (_, mut s) in lights.iter_mut(world) {
        *s = settings;
    }
}
