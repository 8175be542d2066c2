//! The viewer in a real window: under the display in `DISPLAY`, or under an Xvfb server this
//! test starts (software Vulkan renders into it). It runs the scripted exercise (resize,
//! minimise to 0×0 and restore, a lost surface, settings changes that recreate the shadow map)
//! with a broken material shader given, and checks that frames kept coming, that the shader
//! error was reported while the shipped pipeline kept drawing, and that the screenshot shows
//! the scene and the inspector. A plain `main` (no test harness), because winit's event loop
//! must own the main thread.

use std::io::{BufRead, BufReader};
use std::path::Path;
use std::process::{Child, Command, Stdio};

use penumbra::viewer::exercise::EXERCISE_TICKS;
use penumbra::viewer::{ViewerOptions, run};

/// An Xvfb server, stopped on drop.
struct Xvfb(Child);

impl Drop for Xvfb {
    fn drop(&mut self) {
        let _ = self.0.kill();
        let _ = self.0.wait();
    }
}

/// Starts Xvfb on a display number of its own choosing (`-displayfd`: the server writes the
/// number once it accepts connections) and returns it with the display name; None when no
/// `Xvfb` is installed.
fn start_xvfb() -> Option<(Xvfb, String)> {
    let mut child = match Command::new("Xvfb")
        .args(["-displayfd", "1", "-screen", "0", "1280x800x24", "-nolisten", "tcp"])
        .stdout(Stdio::piped())
        .stderr(Stdio::null())
        .spawn()
    {
        Ok(child) => child,
        Err(e) if e.kind() == std::io::ErrorKind::NotFound => return None,
        Err(e) => panic!("cannot start Xvfb: {e}"),
    };
    let stdout = child.stdout.take().expect("piped stdout");
    let server = Xvfb(child);
    let mut line = String::new();
    BufReader::new(stdout)
        .read_line(&mut line)
        .expect("Xvfb reports its display number");
    let number: u32 = line
        .trim()
        .parse()
        .unwrap_or_else(|_| panic!("Xvfb did not start (it wrote {line:?})"));
    Some((server, format!(":{number}")))
}

/// An X server for the window: the one in `DISPLAY`, else an Xvfb this test starts. None
/// (after saying why the test is skipped) where neither is available. Other platforms
/// (Windows, macOS) open the window on their own desktop.
fn x_server() -> Result<Option<Xvfb>, String> {
    if cfg!(not(all(unix, not(target_os = "macos")))) || std::env::var_os("DISPLAY").is_some() {
        return Ok(None);
    }
    match start_xvfb() {
        Some((server, display)) => {
            // SAFETY: single-threaded here; nothing else reads the environment concurrently.
            unsafe { std::env::set_var("DISPLAY", display) };
            Ok(Some(server))
        }
        None => Err("DISPLAY is not set and no Xvfb is installed (on Debian/Ubuntu: \
                     apt-get install xvfb)"
            .to_owned()),
    }
}

fn main() {
    let _server = match x_server() {
        Ok(server) => server,
        Err(why) => {
            println!("viewer_window: SKIPPED, no X server can be started: {why}");
            return;
        }
    };
    // SAFETY: as above.
    unsafe { std::env::remove_var("WAYLAND_DISPLAY") };

    let temp = std::env::temp_dir();
    let screenshot = temp.join(format!("penumbra-viewer-{}.png", std::process::id()));
    // A material shader with an error: reported, and the shipped pipeline keeps drawing.
    let shader = temp.join(format!("penumbra-viewer-broken-{}.wgsl", std::process::id()));
    std::fs::write(&shader, "@fragment fn fs_main( -> @location(0) vec4<f32> {}").unwrap();
    let options = ViewerOptions {
        width: 640,
        height: 360,
        exit_after: Some(4),
        screenshot: Some(screenshot.clone()),
        shader: Some(shader.clone()),
        exercise: true,
        ..ViewerOptions::default()
    };
    let summary = run(Path::new("assets/scenes/default.ron"), options).unwrap_or_else(|e| {
        panic!(
            "the viewer failed: {e}\nIt needs a Vulkan driver (on Debian/Ubuntu: apt-get install \
             mesa-vulkan-drivers) and X11 client libraries (libx11-xcb1, libxkbcommon-x11-0)."
        )
    });
    println!("viewer: {summary:?}");
    assert!(summary.ticks >= EXERCISE_TICKS, "{summary:?}");
    // The broken shader's compose error, naming its file, is still shown on the last tick.
    let name = shader.display().to_string();
    assert!(
        summary
            .errors
            .iter()
            .any(|e| e.contains(&name) && e.contains("failed to compose")),
        "the shader error was not reported: {:?}",
        summary.errors
    );
    // Minimised ticks and the lost surface are skipped, every other tick draws.
    assert!(summary.frames >= summary.ticks - 6, "{summary:?}");
    assert!(
        summary.surface_recoveries >= 1,
        "the lost surface was not recovered: {summary:?}"
    );
    let image = image::open(summary.screenshot.as_ref().expect("a screenshot"))
        .expect("the screenshot is a PNG")
        .to_rgb8();
    let (w, h) = image.dimensions();
    assert!(w >= 200 && h >= 150, "{w}×{h}");
    // Left: the inspector's dark panel. Right: the scene, clearly brighter on average.
    let mean = |x0: u32, x1: u32| {
        let mut sum = 0.0;
        let mut n = 0.0;
        for y in 0..h {
            for x in x0..x1 {
                let p = image.get_pixel(x, y);
                sum += (p[0] as f64 + p[1] as f64 + p[2] as f64) / 3.0;
                n += 1.0;
            }
        }
        sum / n
    };
    let panel = mean(0, w / 8);
    let scene = mean(w - w / 4, w);
    assert!(panel < 60.0, "no inspector panel on the left (mean {panel})");
    assert!(
        scene > panel + 40.0,
        "no scene on the right (mean {scene}, panel {panel})"
    );
    let _ = std::fs::remove_file(&screenshot);
    let _ = std::fs::remove_file(&shader);
    println!("viewer_window: 1 passed, 0 failed");
}
