//! Tests of the culling chunks: building and refitting them, and chunked culling (cascade
//! boxes, masked visits, frustum, light range) finding exactly what the member tests find.

use super::*;
use crate::math::aabb::Aabb;
use crate::math::cascades::{CascadeFit, CascadeInput, compute_cascades};
use crate::math::frustum::CameraView;
use glam::{Mat4, Quat};

#[test]
fn the_range_cull_keeps_exactly_the_spheres_that_touch_the_light_sphere() {
    let (centers, mut radii) = grid();
    radii[5] = f32::NAN;
    let chunks = SphereChunks::build(&centers, &radii);
    let mut out = Vec::new();
    for (center, range) in [(Vec3::new(0.0, 2.0, 0.0), 30.0), (Vec3::new(-150.0, 5.0, 60.0), 80.0)] {
        cull_spheres_sphere_chunked(center, range, &centers, &radii, &chunks, &mut out);
        let brute: Vec<u32> = (0..centers.len())
            .filter(|&i| radii[i].is_finite() && centers[i].distance(center) <= range + radii[i])
            .map(|i| i as u32)
            .collect();
        assert_eq!(out, brute);
        assert!(!out.is_empty() && out.len() < centers.len());
    }
    cull_spheres_sphere_chunked(Vec3::NAN, 5.0, &centers, &radii, &chunks, &mut out);
    assert!(out.is_empty());
}

#[test]
fn refitting_the_chunks_of_moved_members_equals_building_again() {
    let (mut centers, mut radii) = grid();
    let mut chunks = SphereChunks::build(&centers, &radii);
    for (i, p, r) in [
        (70, Vec3::new(900.0, 3.0, -40.0), 2.0),
        (64, Vec3::ZERO, 0.1),
        (39_999, Vec3::splat(-7.0), 9.0),
    ] {
        centers[i] = p;
        radii[i] = r;
        chunks.refit(i, &centers, &radii);
    }
    assert_eq!(chunks, SphereChunks::build(&centers, &radii));
    // Members appended: the chunks from the last partial one on are made again.
    let (mut more, mut more_radii) = (centers.clone(), radii.clone());
    more.extend([Vec3::ONE; 100]);
    more_radii.extend([0.5; 100]);
    let mut grown = chunks.clone();
    grown.rebuild_from(centers.len() / CHUNK, &more, &more_radii);
    assert_eq!(grown, SphereChunks::build(&more, &more_radii));
    radii[3] = f32::NAN;
    chunks.refit(3, &centers, &radii);
    assert!(chunks.radii[0].is_infinite() && chunks.boxes[0].is_empty());
    // Past the end: nothing changes.
    chunks.refit(1_000_000, &centers, &radii);
    assert_eq!(chunks, SphereChunks::build(&centers, &radii));
}

/// A grid of spheres over a 400 m square, in row order (spatially coherent chunks).
fn grid() -> (Vec<Vec3>, Vec<f32>) {
    let mut centers = Vec::new();
    let mut radii = Vec::new();
    for i in 0..200 {
        for j in 0..200 {
            centers.push(Vec3::new(
                i as f32 * 2.0 - 200.0,
                0.5 + (j % 7) as f32,
                j as f32 * 2.0 - 200.0,
            ));
            radii.push(0.3 + (i % 5) as f32 * 0.2);
        }
    }
    (centers, radii)
}

fn camera() -> CameraView {
    CameraView {
        world_from_view: Mat4::from_rotation_translation(Quat::from_rotation_y(0.7), Vec3::new(10.0, 2.0, 30.0)),
        fov_y: 1.0,
        aspect: 1.7,
        near: 0.1,
        far: 300.0,
    }
}

#[test]
fn chunk_spheres_contain_their_members() {
    let (centers, radii) = grid();
    let chunks = SphereChunks::build(&centers, &radii);
    assert_eq!(chunks.len(), centers.len().div_ceil(CHUNK));
    for (i, (c, r)) in centers.iter().zip(&radii).enumerate() {
        let k = i / CHUNK;
        assert!(c.distance(chunks.centers[k]) + r <= chunks.radii[k]);
    }
    let mut bad = centers.clone();
    bad[70] = Vec3::NAN;
    assert_eq!(SphereChunks::build(&bad, &radii).radii[1], f32::INFINITY);
}

/// `count` cascades to `max_distance` of the test camera over the grid.
fn cascades(count: usize, max_distance: f32) -> CascadeSet {
    compute_cascades(&CascadeInput {
        camera: camera(),
        light_direction: Vec3::new(0.3, -0.8, 0.2),
        scene_bounds: Aabb::new(Vec3::splat(-210.0), Vec3::splat(210.0)),
        receiver_bounds: Aabb::EMPTY,
        count,
        split_lambda: 0.6,
        max_distance,
        resolution: 2048,
        fit: CascadeFit::Tight,
        angular_diameter: 0.01,
        blend_width: 0.0,
        snap_cells: 0,
        scroll: false,
        seen: None,
    })
}

#[test]
fn chunked_cascade_culling_keeps_every_exact_hit() {
    let (centers, radii) = grid();
    let chunks = SphereChunks::build(&centers, &radii);
    let set = cascades(4, 150.0);
    let mut exact = vec![0u8; centers.len()];
    let mut chunked = vec![0u8; centers.len()];
    cull_casters(&set, &centers, &radii, &mut exact);
    cull_casters_chunked(&set, &centers, &radii, &chunks, &mut chunked);
    let mut extra = 0;
    for (e, c) in exact.iter().zip(&chunked) {
        assert_eq!(e & !c, 0, "a chunk dropped an exact hit");
        extra += (c & !e).count_ones();
    }
    // Whole-chunk acceptance only happens when the chunk is inside the box, where every
    // member is inside too: no extra bits at all.
    assert_eq!(extra, 0);
    assert!(exact.iter().any(|&m| m != 0) && exact.contains(&0));
}

#[test]
fn visiting_the_reached_chunks_gives_the_chunked_masks() {
    let (centers, radii) = grid();
    let chunks = SphereChunks::build(&centers, &radii);
    let set = cascades(2, 40.0);
    let mut chunked = vec![0u8; centers.len()];
    cull_casters_chunked(&set, &centers, &radii, &chunks, &mut chunked);
    let mut visited = vec![0u8; centers.len()];
    let mut calls = 0;
    visit_casters_chunked(&set, &centers, &radii, &chunks, |start, masks| {
        visited[start..start + masks.len()].copy_from_slice(masks);
        calls += 1;
    });
    assert_eq!(visited, chunked);
    let reached = chunked.chunks(CHUNK).filter(|c| c.iter().any(|&m| m != 0)).count();
    assert!(
        calls >= reached && calls < chunks.centers.len(),
        "{calls} of {} chunks visited",
        chunks.centers.len()
    );
}

#[test]
fn a_masked_visit_gives_the_full_visits_bits_in_its_mask() {
    let (centers, radii) = grid();
    let chunks = SphereChunks::build(&centers, &radii);
    let set = cascades(4, 150.0);
    let mut full = vec![None; chunks.len()];
    visit_cascade_chunks(&set, &chunks, (centers.len(), u8::MAX), |k, o, i| {
        full[k] = Some((o, i))
    });
    for mask in [0b0001u8, 0b0011, 0b1000, 0b0110] {
        let mut masked = vec![None; chunks.len()];
        visit_cascade_chunks(&set, &chunks, (centers.len(), mask), |k, o, i| masked[k] = Some((o, i)));
        let want: Vec<_> = (full.iter())
            .map(|v| v.map(|(o, i)| (o & mask, i & mask)).filter(|&(o, _)| o != 0))
            .collect();
        assert_eq!(masked, want, "mask {mask:04b}");
        let visited = masked.iter().flatten().count();
        assert!(
            visited > 0 && visited < full.iter().flatten().count(),
            "mask {mask:04b}: {visited}"
        );
    }
}

#[test]
fn chunked_frustum_culling_matches_the_exact_test() {
    let (centers, radii) = grid();
    let chunks = SphereChunks::build(&centers, &radii);
    let frustum = Frustum::from_clip_from_world(camera().clip_from_world());
    let (mut exact, mut chunked, mut scratch) = (Vec::new(), Vec::new(), Vec::new());
    cull_spheres_frustum(&frustum, &centers, &radii, &mut exact);
    cull_spheres_frustum_chunked(&frustum, &centers, &radii, &chunks, &mut chunked, &mut scratch);
    assert_eq!(exact, chunked);
    assert!(!exact.is_empty() && exact.len() < centers.len());
}
