//! Files named by user data stay inside the asset root: glTF URIs and scene paths that are
//! absolute, step out with `..` (plainly, percent-encoded or through a symbolic link) or name
//! a non-regular file are refused with a message that tells nothing about the target; reads
//! are bounded; one file reached by several spellings is loaded once.

use std::fs;
use std::path::{Path, PathBuf};

use gltf::json;
use penumbra::app::{PreparedScene, SpawnError};
use penumbra::asset_io::{AssetError, AssetIo};
use penumbra::gltf::{load, load_with};
use penumbra::scene::SceneDesc;

/// A scratch tree: `<tmp>/confined/` is the asset root (the model's folder), with a secret file
/// beside it, outside.
struct Tree(PathBuf);

impl Tree {
    fn new(name: &str) -> Self {
        let dir = std::env::temp_dir().join(format!("penumbra-confine-{}-{name}", std::process::id()));
        let _ = fs::remove_dir_all(&dir);
        fs::create_dir_all(dir.join("confined/sub")).unwrap();
        fs::write(dir.join("secret.bin"), vec![7u8; 4096]).unwrap();
        for file in ["fern.bin", "fern_leaf.png"] {
            fs::copy(Path::new("assets/models").join(file), dir.join("confined").join(file)).unwrap();
        }
        Self(dir)
    }

    fn root(&self) -> PathBuf {
        self.0.join("confined")
    }

    /// A special (non-regular) file at `path`: a Unix socket, the one kind std can create.
    fn socket(&self, path: &Path) -> std::os::unix::net::UnixListener {
        std::os::unix::net::UnixListener::bind(path).expect("a socket can be bound in the scratch tree")
    }

    /// Writes the sample model with its JSON edited, as `confined/model.gltf`.
    fn model(&self, edit: impl FnOnce(&mut json::Root)) -> PathBuf {
        let text = fs::read_to_string("assets/models/fern.gltf").unwrap();
        let mut root: json::Root = json::deserialize::from_str(&text).unwrap();
        edit(&mut root);
        let path = self.root().join("model.gltf");
        fs::write(&path, json::serialize::to_string(&root).unwrap()).unwrap();
        path
    }
}

impl Drop for Tree {
    fn drop(&mut self) {
        let _ = fs::remove_dir_all(&self.0);
    }
}

/// The error text after the model's own path.
fn model_error(path: &Path) -> String {
    let err = load(path).expect_err("the model loads");
    let text = err.to_string();
    text.strip_prefix(&format!("{}: ", path.display()))
        .unwrap_or(&text)
        .to_owned()
}

#[test]
fn buffer_uris_outside_the_root_are_refused_without_revealing_the_target() {
    let tree = Tree::new("buffers");
    let secret = tree.0.join("secret.bin").display().to_string();
    // Absolute paths are refused even when they name a file inside the root; a special file
    // outside it is refused without being opened.
    let inside = fs::canonicalize(tree.root().join("fern.bin"))
        .unwrap()
        .display()
        .to_string();
    let _socket = tree.socket(&tree.0.join("outside.sock"));
    let special = tree.0.join("outside.sock").display().to_string();
    let outside = format!(
        "outside the asset folder `{}` (only relative paths inside it are read)",
        fs::canonicalize(tree.root()).unwrap().display()
    );
    for uri in [
        "../secret.bin",
        "../absent.bin",
        "%2e%2e/secret.bin",
        "sub/%2E%2E/%2e%2e/secret.bin",
        "./../secret.bin",
        secret.as_str(),
        inside.as_str(),
        special.as_str(),
    ] {
        let path = tree.model(|root| root.buffers[0].uri = Some(uri.to_owned()));
        let err = model_error(&path);
        // The same words whether the target exists or not: only the URI differs.
        assert_eq!(err, format!("buffer 0 (`{uri}`): {outside}"));
    }
}

#[test]
fn symbolic_links_out_of_the_root_and_special_files_are_refused() {
    let tree = Tree::new("links");
    std::os::unix::fs::symlink(tree.0.join("secret.bin"), tree.root().join("link.bin")).unwrap();
    let _outside = tree.socket(&tree.0.join("outside.sock"));
    std::os::unix::fs::symlink(tree.0.join("outside.sock"), tree.root().join("special.bin")).unwrap();
    for uri in ["link.bin", "special.bin"] {
        let path = tree.model(|root| root.buffers[0].uri = Some(uri.to_owned()));
        let err = model_error(&path);
        assert!(err.contains(": outside the asset folder `"), "{uri}: {err}");
    }
    // A folder and a special file inside the root.
    let path = tree.model(|root| root.images[0].uri = Some("sub".to_owned()));
    assert_eq!(model_error(&path), "image 0 (`sub`): not a regular file");
    let _inside = tree.socket(&tree.root().join("inside.sock"));
    let path = tree.model(|root| root.buffers[0].uri = Some("inside.sock".to_owned()));
    assert_eq!(model_error(&path), "buffer 0 (`inside.sock`): not a regular file");
    // A link that stays inside the root is followed.
    std::os::unix::fs::symlink(tree.root().join("fern.bin"), tree.root().join("sub/again.bin")).unwrap();
    let path = tree.model(|root| root.buffers[0].uri = Some("sub/again.bin".to_owned()));
    assert!(load(&path).is_ok());
}

#[test]
fn reads_stop_at_the_declared_length_and_the_size_cap() {
    let tree = Tree::new("bounded");
    // A buffer file much longer than declared: only the declared bytes are read.
    let mut bin = fs::read(tree.root().join("fern.bin")).unwrap();
    let declared = bin.len();
    bin.resize(declared + (8 << 20), 0);
    fs::write(tree.root().join("fern.bin"), &bin).unwrap();
    let path = tree.model(|_| {});
    assert!(load(&path).is_ok());
    // A buffer declared and stored at 8 MiB, under a 1 MiB cap.
    let big = bin.len() as u64;
    let path = tree.model(|root| root.buffers[0].byte_length = json::validation::USize64(big));
    let mut io = AssetIo::for_file(&path);
    io.max_file_bytes = 1 << 20;
    let err = load_with(&path, &io).expect_err("capped").to_string();
    assert!(
        err.ends_with(&format!(
            "buffer 0 (`fern.bin`): {big} bytes, more than the 1048576 bytes allowed"
        )),
        "{err}"
    );
    // Decoding is bounded too.
    let mut io = AssetIo::for_file(&path);
    io.max_image_bytes = 1000;
    let err = load_with(&path, &io).expect_err("image cap").to_string();
    assert!(err.contains("image 0 (`fern_leaf.png`): cannot decode: "), "{err}");
    assert!(err.contains("more than the 1000 allowed"), "{err}");
}

#[test]
fn one_image_file_under_several_spellings_is_decoded_once() {
    let tree = Tree::new("dedup");
    let path = tree.model(|root| {
        let first = root.images[0].clone();
        for uri in ["./fern_leaf.png", "sub/../fern_leaf.png", "fern%5fleaf.png"] {
            let mut image = first.clone();
            image.uri = Some(uri.to_owned());
            root.images.push(image);
            let mut texture = root.textures[0].clone();
            texture.source = json::Index::new(root.images.len() as u32 - 1);
            root.textures.push(texture);
            let textured = root
                .materials
                .iter()
                .find(|m| m.pbr_metallic_roughness.base_color_texture.is_some());
            let mut material = textured.expect("the sample has a textured material").clone();
            let info = material.pbr_metallic_roughness.base_color_texture.as_mut().unwrap();
            info.index = json::Index::new(root.textures.len() as u32 - 1);
            root.materials.push(material);
        }
    });
    let model = load(&path).unwrap();
    assert_eq!(model.images.len(), 1, "decoded once");
    let textured: Vec<_> = model.materials.iter().filter_map(|m| m.base_color_texture).collect();
    assert_eq!(textured, [0, 0, 0, 0], "four materials share the one image");
}

#[test]
fn scene_textures_and_models_stay_inside_the_root() {
    let tree = Tree::new("scene");
    fs::copy("assets/models/fern.gltf", tree.root().join("fern.gltf")).unwrap();
    let scene = |texture: &str, model: &str| {
        let text = format!(
            r#"Scene(
    camera: (position: (0, 2, 5), target: (0, 0, 0), fov: 60, near: 0.1, far: 100),
    sun: (direction: (0, -1, 0)),
    materials: {{ "m": (texture: "{texture}"), "plain": () }},
    objects: [(shape: Gltf(path: "{model}"), material: "plain")],
)"#
        );
        let path = tree.root().join("scene.ron");
        fs::write(&path, text).unwrap();
        path
    };
    // NOTE: read without the scene's own file checks, to reach the loader's.
    let prepare = |path: &Path| {
        let mut desc = SceneDesc::from_str(&fs::read_to_string(path).unwrap(), "scene.ron").unwrap();
        desc.base_dir = tree.root();
        PreparedScene::new(&desc)
    };
    assert!(prepare(&scene("fern_leaf.png", "fern.gltf")).is_ok());
    assert!(prepare(&scene("./sub/../fern_leaf.png", "sub/../fern.gltf")).is_ok());
    let _socket = tree.socket(&tree.0.join("outside.sock"));
    let special = tree.0.join("outside.sock").display().to_string();
    let err = prepare(&scene("fern_leaf.png", &special)).map(|_| ()).unwrap_err();
    assert!(matches!(err, SpawnError::Model { object: 0, .. }), "{err}");
    assert!(err.to_string().contains("outside the asset folder"), "{err}");
    // The scene check itself does not look outside: a missing and an existing outside file
    // read the same.
    let texts: Vec<String> = ["../secret.bin", "../absent.png"]
        .iter()
        .map(|t| prepare(&scene(t, "fern.gltf")).map(|_| ()).unwrap_err().to_string())
        .collect();
    assert_eq!(
        texts[0].replace("../secret.bin", "X"),
        texts[1].replace("../absent.png", "X")
    );
    assert!(texts[0].contains("outside the asset folder"), "{}", texts[0]);
}

#[test]
fn resolve_refuses_what_it_must() {
    let tree = Tree::new("resolve");
    let io = AssetIo::with_root(tree.root());
    let dir = tree.root().join("sub");
    assert!(io.resolve(&dir, "../fern.bin").is_ok());
    let absolute = fs::canonicalize(tree.root().join("fern.bin"))
        .unwrap()
        .display()
        .to_string();
    for bad in ["../../secret.bin", "", absolute.as_str(), "a\0b"] {
        assert!(
            matches!(io.resolve(&dir, bad), Err(AssetError::Outside { .. })),
            "{bad:?}"
        );
    }
    assert!(matches!(
        io.resolve(&dir, "nothing.png"),
        Err(AssetError::Missing { .. })
    ));
    // A folder outside the root cannot be a starting point either.
    assert!(matches!(
        io.resolve(&tree.0, "secret.bin"),
        Err(AssetError::Outside { .. })
    ));
    let same = [io.resolve(&dir, "../fern.bin"), io.resolve(&tree.root(), "./fern.bin")];
    assert_eq!(same[0], same[1]);
}

#[test]
fn the_default_root_is_the_enclosing_assets_folder() {
    let io = AssetIo::for_file(Path::new("assets/scenes/garden.ron"));
    assert_eq!(io.root(), fs::canonicalize("assets").unwrap());
    // Outside any `assets` folder, the file's own folder.
    let tree = Tree::new("default-root");
    let io = AssetIo::for_file(&tree.root().join("sub/model.gltf"));
    assert_eq!(io.root(), fs::canonicalize(tree.root().join("sub")).unwrap());
}
