//! The compute skinning kernel on a real wgpu device (lavapipe in CI) against its CPU mirror:
//! the walker posed at several times of its walk, two jobs in one dispatch (the second
//! written after the first), every skinned position and normal compared.

use bytemuck::cast_slice;
use glam::{Mat4, Vec3};
use penumbra::gltf::sample::SAMPLE_DIR;
use penumbra::gltf::sample::walker::WALKER_GLTF;
use penumbra::math::skinning::{skin_normal, skin_position};
use penumbra::mesh::Vertex;
use penumbra::render::Renderer;
use penumbra::render::readback::read_buffer;
use penumbra::render::skinning::{SkinJobGpu, SkinningBuffers, SkinningKernel, pack_influences};
use penumbra::shader::ShaderLibrary;
use wgpu::util::DeviceExt;

#[test]
fn gpu_skinned_vertices_match_the_cpu_mirror() {
    let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
        .join(SAMPLE_DIR)
        .join(WALKER_GLTF);
    let model = penumbra::gltf::load(&path).unwrap_or_else(|e| panic!("{e}"));
    let body = model.nodes.iter().find(|n| n.skin.is_some()).expect("a skinned node");
    let primitive = &model.meshes[body.mesh].primitives[0];
    let influences = primitive.influences.as_ref().expect("skinned");
    let vertices = &primitive.mesh.vertices;
    let n = vertices.len() as u32;
    // Two poses, one job each: the same vertices, the second pose's joints after the first's.
    let poses: Vec<Vec<Mat4>> = [0.3, 2.6]
        .iter()
        .map(|&t| model.skin_matrices(0, &model.model_from_nodes(&model.local_pose(Some(0), t))))
        .collect();
    let joints: Vec<Mat4> = poses.concat();
    let jobs = [
        SkinJobGpu {
            source_first: 0,
            vertex_count: n,
            joint_first: 0,
            dest_first: 0,
        },
        SkinJobGpu {
            source_first: 0,
            vertex_count: n,
            joint_first: poses[0].len() as u32,
            dest_first: n,
        },
    ];

    let renderer = Renderer::headless(8, 8)
        .expect("no GPU adapter: install a Vulkan driver (on Debian/Ubuntu: apt-get install mesa-vulkan-drivers)");
    let (device, queue) = (&renderer.gpu.device, &renderer.gpu.queue);
    let mut library = ShaderLibrary::new().expect("shader library");
    let kernel = SkinningKernel::new(device, &mut library);
    let storage = |label, bytes: &[u8]| {
        device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
            label: Some(label),
            contents: bytes,
            usage: wgpu::BufferUsages::STORAGE,
        })
    };
    let bind_pose = storage("bind pose", cast_slice(vertices));
    let packed = storage("influences", cast_slice(&pack_influences(influences)));
    let joint_buffer = storage("joints", cast_slice(&joints));
    let job_buffer = storage("jobs", cast_slice(&jobs));
    let size = u64::from(2 * n) * size_of::<Vertex>() as u64;
    let posed = device.create_buffer(&wgpu::BufferDescriptor {
        label: Some("posed"),
        size,
        usage: wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_SRC | wgpu::BufferUsages::VERTEX,
        mapped_at_creation: false,
    });
    let readback = device.create_buffer(&wgpu::BufferDescriptor {
        label: Some("readback"),
        size,
        usage: wgpu::BufferUsages::MAP_READ | wgpu::BufferUsages::COPY_DST,
        mapped_at_creation: false,
    });
    let mut encoder = device.create_command_encoder(&Default::default());
    let buffers = SkinningBuffers {
        bind_pose: &bind_pose,
        influences: &packed,
        joints: &joint_buffer,
        jobs: &job_buffer,
        posed: &posed,
    };
    let group = kernel.bind_group(device, &buffers);
    kernel.record(&mut encoder, &group, (2, n), None);
    encoder.copy_buffer_to_buffer(&posed, 0, &readback, 0, size);
    queue.submit([encoder.finish()]);
    let bytes = read_buffer(device, &readback, size).expect("read back");
    let gpu: &[Vertex] = cast_slice(&bytes);

    let mut worst = (0.0f32, 0.0f32);
    for (job, pose) in poses.iter().enumerate() {
        for (k, (v, i)) in vertices.iter().zip(influences).enumerate() {
            let out = gpu[job * n as usize + k];
            let p = skin_position(Vec3::from(v.position), i, pose);
            let normal = skin_normal(Vec3::from(v.normal), i, pose);
            worst.0 = worst.0.max((Vec3::from(out.position) - p).length());
            worst.1 = worst.1.max((Vec3::from(out.normal) - normal).length());
            assert_eq!(out.uv, v.uv, "job {job} vertex {k}: uv");
        }
    }
    eprintln!("largest position difference {} m, normal {}", worst.0, worst.1);
    assert!(worst.0 < 7.5e-7 && worst.1 < 1e-6, "GPU and CPU differ by {worst:?}");
    // The pose moved the vertices: the comparison was not of the bind pose with itself.
    let moved = vertices
        .iter()
        .zip(&gpu[n as usize..])
        .filter(|(a, b)| (Vec3::from(a.position) - Vec3::from(b.position)).length() > 0.5)
        .count();
    assert!(moved as u32 > n / 2, "only {moved} of {n} vertices moved");
}
