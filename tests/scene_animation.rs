//! A scene file's `animation` on a glTF object: the clip is picked by name, copies of a grid
//! start `stagger` seconds apart, `playing: false` holds the start pose; a clip the model does
//! not have is a spawn error naming it and the clips it has, and an animation on a primitive
//! shape or with a negative start is a located scene error.

use bevy_app::App;
use penumbra::app::spawn_scene;
use penumbra::ecs::plugin::ShadowPlugin;
use penumbra::ecs::skinning::AnimationPlayer;
use penumbra::gltf::sample::walker::WALK_DURATION;
use penumbra::scene::SceneDesc;

/// A scene of walkers (from `assets/scenes`), the last object written as `walkers`.
fn scene(walkers: &str) -> String {
    format!(
        r#"Scene(
    camera: (position: (0, 2, 6), target: (0, 1, 0), fov: 50, near: 0.1, far: 100),
    sun: (direction: (0.3, -1, -0.4)),
    materials: {{ "white": () }},
    objects: [
        (shape: Plane(size: (10, 10)), material: "white"),
        {walkers},
    ],
)"#
    )
}

/// The scene parsed, its models found in `assets/scenes`' folder.
fn desc(walkers: &str) -> SceneDesc {
    let mut desc = SceneDesc::from_str(&scene(walkers), "walkers.ron").unwrap_or_else(|e| panic!("{e}"));
    desc.base_dir = "assets/scenes".into();
    desc
}

/// The players spawned, in spawn order.
fn players(walkers: &str) -> Vec<AnimationPlayer> {
    let mut app = App::new();
    app.add_plugins(ShadowPlugin);
    spawn_scene(app.world_mut(), &desc(walkers)).unwrap_or_else(|e| panic!("{e}"));
    let world = app.world_mut();
    world.query::<&AnimationPlayer>().iter(world).copied().collect()
}

#[test]
fn grid_copies_start_staggered_at_the_named_clip() {
    let walkers = r#"(shape: Gltf(path: "../models/walker.gltf"), material: "white", grid: (count: (3, 1, 1), spacing: (1, 0, 0)),
        animation: (clip: "walk", speed: 0.5, start: 1, stagger: 3.5, playing: false))"#;
    let mut found = players(walkers);
    // Two skinned primitives per walker.
    assert_eq!(found.len(), 6, "{found:?}");
    found.sort_by(|a, b| a.time.total_cmp(&b.time));
    let times: Vec<f32> = found.iter().map(|p| p.time).collect();
    // Starts 1, 4.5 and 8 s; the last wraps into the 8 s walk.
    let expected = [1.0, 4.5, 8.0].map(|t: f32| t.rem_euclid(WALK_DURATION));
    let mut expected: Vec<f32> = expected.iter().flat_map(|&t| [t, t]).collect();
    expected.sort_by(f32::total_cmp);
    for (t, e) in times.iter().zip(&expected) {
        assert!((t - e).abs() < 1e-5, "times {times:?}, expected {expected:?}");
    }
    assert!(
        found
            .iter()
            .all(|p| p.paused && p.speed == 0.5 && p.looping && p.clip == Some(0))
    );
}

#[test]
fn without_an_animation_the_first_clip_plays_from_the_start() {
    let found = players(r#"(shape: Gltf(path: "../models/walker.gltf"), material: "white")"#);
    assert_eq!(found.len(), 2);
    assert!(found.iter().all(|p| *p == AnimationPlayer::default()), "{found:?}");
}

#[test]
fn an_unknown_clip_is_a_spawn_error_listing_the_clips() {
    let walkers = r#"(shape: Gltf(path: "../models/walker.gltf"), material: "white", animation: (clip: "run"))"#;
    let mut app = App::new();
    app.add_plugins(ShadowPlugin);
    let err = spawn_scene(app.world_mut(), &desc(walkers)).expect_err("no clip named run");
    let msg = err.to_string();
    for part in ["object 1", "no animation named \"run\"", "\"walk\""] {
        assert!(msg.contains(part), "`{part}` not in: {msg}");
    }
}

#[test]
fn an_animation_on_a_primitive_or_a_negative_start_is_located() {
    let text = scene(
        r#"(shape: Cuboid(size: (1, 1, 1)), material: "white", animation: ()),
        (shape: Gltf(path: "../models/walker.gltf"), material: "white", animation: (start: -2, speed: inf))"#,
    );
    let msg = SceneDesc::from_str(&text, "walkers.ron")
        .expect_err("two problems")
        .to_string();
    for part in [
        "walkers.ron:7:72:",
        "only a `Gltf` shape's skinned meshes animate",
        "`objects[1].animation`",
        "walkers.ron:8:92:",
        "finite seconds ≥ 0",
        "`objects[2].animation.start`",
        "found -2",
        "`objects[2].animation.speed`",
    ] {
        assert!(msg.contains(part), "`{part}` not in: {msg}");
    }
}

/// Runs `penumbra render` with `args`; its stdout and stderr, and whether it succeeded.
fn render(args: &[&str]) -> (String, String, bool) {
    let out = std::process::Command::new(env!("CARGO_BIN_EXE_penumbra"))
        .arg("render")
        .args(args)
        .env("XDG_RUNTIME_DIR", std::env::temp_dir())
        .output()
        .expect("runs penumbra");
    let text = |b: &[u8]| String::from_utf8_lossy(b).into_owned();
    (text(&out.stdout), text(&out.stderr), out.status.success())
}

#[test]
fn animation_speed_zero_poses_once_and_a_bad_speed_is_refused() {
    let image = std::env::temp_dir().join(format!("penumbra-animation-{}.png", std::process::id()));
    let image = image.to_string_lossy().into_owned();
    let scene = "assets/scenes/walkers.ron";
    let base = [
        scene, "--width", "160", "--height", "90", "--frames", "3", "--json", "--out", &image,
    ];
    let (stdout, stderr, ok) = render(&[&base[..], &["--animation-speed", "0"]].concat());
    assert!(ok, "{stderr}");
    let json: serde_json::Value = serde_json::from_str(&stdout).expect("one JSON object");
    assert_eq!(
        json["skinned_meshes_posed_per_frame"],
        serde_json::json!([12, 0, 0]),
        "{stdout}"
    );
    let (stdout, stderr, ok) = render(&base);
    assert!(ok, "{stderr}");
    let json: serde_json::Value = serde_json::from_str(&stdout).expect("one JSON object");
    assert_eq!(
        json["skinned_meshes_posed_per_frame"],
        serde_json::json!([12, 12, 12]),
        "{stdout}"
    );
    let (_, stderr, ok) = render(&[&base[..], &["--animation-speed", "inf"]].concat());
    assert!(!ok);
    assert!(stderr.contains("expected a finite number, found `inf`"), "{stderr}");
    let _ = std::fs::remove_file(&image);
}
