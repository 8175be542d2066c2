//! The naga_oil composer holding penumbra's WGSL modules, and the entry points that build
//! and validate each shader.

use std::collections::HashMap;

use naga::valid::{Capabilities, ValidationFlags, Validator};
use naga_oil::compose::{ComposableModuleDescriptor, Composer, NagaModuleDescriptor, ShaderLanguage, ShaderType};
use thiserror::Error;

use crate::layout::group;
use crate::shader::contract;
use crate::shader::variant::ForwardVariant;

/// A shader that failed to compose or validate.
#[derive(Debug, Error)]
#[non_exhaustive]
pub enum ShaderError {
    /// naga_oil could not parse or link a module; the message holds the located WGSL error.
    #[error("shader `{file}` failed to compose:\n{message}")]
    Compose {
        /// File the failing module came from.
        file: String,
        /// naga_oil's rendered diagnostic.
        message: String,
    },
    /// The composed module broke a WGSL validation rule.
    #[error("shader `{file}` failed validation: {message}")]
    Validate {
        /// Shader being validated.
        file: String,
        /// naga's validation error.
        message: String,
    },
}

/// A shared WGSL module: its file name and source.
struct ModuleSource {
    file: &'static str,
    source: &'static str,
}

/// Modules generated from Rust descriptions (file name, builder): the constants both sides
/// share, registered first, and the shadow bind group's declarations, registered after
/// [`BEFORE_BINDINGS`] (the types they name).
const CONTRACT: (&str, fn() -> String) = ("contract.wgsl (generated)", contract::wgsl);
const BINDINGS: (&str, fn() -> String) = ("shadows/bindings.wgsl (generated)", group::wgsl);

/// How many of [`MODULES`] the bindings' declarations need.
const BEFORE_BINDINGS: usize = 3;

/// Import modules, in dependency order.
const MODULES: [ModuleSource; 18] = [
    ModuleSource {
        file: "frame.wgsl",
        source: include_str!("../../shaders/frame.wgsl"),
    },
    ModuleSource {
        file: "normal_packing.wgsl",
        source: include_str!("../../shaders/normal_packing.wgsl"),
    },
    ModuleSource {
        file: "shadows/types.wgsl",
        source: include_str!("../../shaders/shadows/types.wgsl"),
    },
    ModuleSource {
        file: "shadows/common.wgsl",
        source: include_str!("../../shaders/shadows/common.wgsl"),
    },
    ModuleSource {
        file: "shadows/moments.wgsl",
        source: include_str!("../../shaders/shadows/moments.wgsl"),
    },
    ModuleSource {
        file: "shadows/msm.wgsl",
        source: include_str!("../../shaders/shadows/msm.wgsl"),
    },
    ModuleSource {
        file: "shadows/page_table.wgsl",
        source: include_str!("../../shaders/shadows/page_table.wgsl"),
    },
    ModuleSource {
        file: "shadows/filters.wgsl",
        source: include_str!("../../shaders/shadows/filters.wgsl"),
    },
    ModuleSource {
        file: "shadows/clipmap.wgsl",
        source: include_str!("../../shaders/shadows/clipmap.wgsl"),
    },
    ModuleSource {
        file: "shadows/cascades.wgsl",
        source: include_str!("../../shaders/shadows/cascades.wgsl"),
    },
    ModuleSource {
        file: "shadows/spot.wgsl",
        source: include_str!("../../shaders/shadows/spot.wgsl"),
    },
    ModuleSource {
        file: "shadows/point.wgsl",
        source: include_str!("../../shaders/shadows/point.wgsl"),
    },
    ModuleSource {
        file: "lights.wgsl",
        source: include_str!("../../shaders/lights.wgsl"),
    },
    ModuleSource {
        file: "shading.wgsl",
        source: include_str!("../../shaders/shading.wgsl"),
    },
    ModuleSource {
        file: "mesh.wgsl",
        source: include_str!("../../shaders/mesh.wgsl"),
    },
    ModuleSource {
        file: "forward_io.wgsl",
        source: include_str!("../../shaders/forward_io.wgsl"),
    },
    ModuleSource {
        file: "indirect.wgsl",
        source: include_str!("../../shaders/indirect.wgsl"),
    },
    ModuleSource {
        file: "contact.wgsl",
        source: include_str!("../../shaders/contact.wgsl"),
    },
];
const FORWARD: ModuleSource = ModuleSource {
    file: "forward.wgsl",
    source: include_str!("../../shaders/forward.wgsl"),
};
const DEFERRED: ModuleSource = ModuleSource {
    file: "deferred.wgsl",
    source: include_str!("../../shaders/deferred.wgsl"),
};
const PROBE: ModuleSource = ModuleSource {
    file: "probe.wgsl",
    source: include_str!("../../shaders/probe.wgsl"),
};
const CASTER: ModuleSource = ModuleSource {
    file: "caster.wgsl",
    source: include_str!("../../shaders/caster.wgsl"),
};
const PREPASS: ModuleSource = ModuleSource {
    file: "prepass.wgsl",
    source: include_str!("../../shaders/prepass.wgsl"),
};
const DEPTH_BOUNDS: ModuleSource = ModuleSource {
    file: "depth_bounds.wgsl",
    source: include_str!("../../shaders/depth_bounds.wgsl"),
};
const SKINNING: ModuleSource = ModuleSource {
    file: "skinning.wgsl",
    source: include_str!("../../shaders/skinning.wgsl"),
};
const OCCLUSION_CULL: ModuleSource = ModuleSource {
    file: "occlusion_cull.wgsl",
    source: include_str!("../../shaders/occlusion_cull.wgsl"),
};
const SHADOW_CULL: ModuleSource = ModuleSource {
    file: "shadow_cull.wgsl",
    source: include_str!("../../shaders/shadow_cull.wgsl"),
};
const OCCLUSION_PYRAMID: ModuleSource = ModuleSource {
    file: "occlusion_pyramid.wgsl",
    source: include_str!("../../shaders/occlusion_pyramid.wgsl"),
};
const SHADOW_CLEAR: ModuleSource = ModuleSource {
    file: "shadow_clear.wgsl",
    source: include_str!("../../shaders/shadow_clear.wgsl"),
};
const SHADOW_SHIFT: ModuleSource = ModuleSource {
    file: "shadow_shift.wgsl",
    source: include_str!("../../shaders/shadow_shift.wgsl"),
};
const SHADOW_MOMENTS: ModuleSource = ModuleSource {
    file: "shadow_moments.wgsl",
    source: include_str!("../../shaders/shadow_moments.wgsl"),
};
const CASCADE_MOMENTS: ModuleSource = ModuleSource {
    file: "shadow_cascade_moments.wgsl",
    source: include_str!("../../shaders/shadow_cascade_moments.wgsl"),
};
const PAGES_ALLOCATE: ModuleSource = ModuleSource {
    file: "pages_allocate.wgsl",
    source: include_str!("../../shaders/pages_allocate.wgsl"),
};
const PAGES_MARK: ModuleSource = ModuleSource {
    file: "pages_mark.wgsl",
    source: include_str!("../../shaders/pages_mark.wgsl"),
};
const PAGES_RENDER: ModuleSource = ModuleSource {
    file: "pages_render.wgsl",
    source: include_str!("../../shaders/pages_render.wgsl"),
};
const RESOLVE: ModuleSource = ModuleSource {
    file: "resolve.wgsl",
    source: include_str!("../../shaders/resolve.wgsl"),
};

/// Holds the composer with every shared module registered.
pub struct ShaderLibrary {
    composer: Composer,
    /// A replacement forward shader (file name, source), if one was set.
    forward_override: Option<(String, String)>,
    /// Bumped whenever the forward shader changes, so cached pipelines are rebuilt.
    forward_generation: u64,
}

impl ShaderLibrary {
    /// Registers the shared modules. Fails only if a shipped shader is broken.
    pub fn new() -> Result<Self, ShaderError> {
        let mut library = Self {
            composer: Composer::default().with_capabilities(capabilities()),
            forward_override: None,
            forward_generation: 0,
        };
        library.add_module(CONTRACT.0, &(CONTRACT.1)())?;
        for (i, module) in MODULES.iter().enumerate() {
            if i == BEFORE_BINDINGS {
                library.add_module(BINDINGS.0, &(BINDINGS.1)())?;
            }
            library.add_module(module.file, module.source)?;
        }
        Ok(library)
    }

    fn add_module(&mut self, file: &str, source: &str) -> Result<(), ShaderError> {
        self.composer
            .add_composable_module(ComposableModuleDescriptor {
                source,
                file_path: file,
                language: ShaderLanguage::Wgsl,
                as_name: None,
                additional_imports: &[],
                shader_defs: HashMap::new(),
            })
            .map(|_| ())
            .map_err(|e| ShaderError::Compose {
                file: file.to_string(),
                message: e.emit_to_string(&self.composer),
            })
    }

    /// Registers a user module (for example a material's own helpers) so shaders composed
    /// later can `#import` it.
    pub fn add_user_module(&mut self, file: &str, source: &str) -> Result<(), ShaderError> {
        self.add_module(file, source)
    }

    /// Composes and validates a shader that may import the library's modules.
    pub fn compose(
        &mut self,
        file: &str,
        source: &str,
        shader_defs: HashMap<String, naga_oil::compose::ShaderDefValue>,
    ) -> Result<naga::Module, ShaderError> {
        let module = self
            .composer
            .make_naga_module(NagaModuleDescriptor {
                source,
                file_path: file,
                shader_type: ShaderType::Wgsl,
                shader_defs,
                additional_imports: &[],
            })
            .map_err(|e| ShaderError::Compose {
                file: file.to_string(),
                message: e.emit_to_string(&self.composer),
            })?;
        validate(file, &module)?;
        Ok(module)
    }

    /// The forward (receiver) shader for one variant: the shipped `forward.wgsl`, or the
    /// source given to [`set_forward_source`](Self::set_forward_source).
    pub fn forward(&mut self, variant: ForwardVariant) -> Result<naga::Module, ShaderError> {
        match self.forward_override.take() {
            Some((file, source)) => {
                let result = self.compose(&file, &source, variant.shader_defs());
                self.forward_override = Some((file, source));
                result
            }
            None => self.compose(FORWARD.file, FORWARD.source, variant.shader_defs()),
        }
    }

    /// The deferred lighting of the prepass's pixels (`deferred.wgsl`) for one forward
    /// variant: the shipped material's lighting, which it shares with the shipped forward
    /// shader; `vs_main` and `fs_main`, and with `compute` also `main` (writing a storage
    /// view of the target).
    pub fn deferred(&mut self, variant: ForwardVariant, compute: bool) -> Result<naga::Module, ShaderError> {
        let mut defs = variant.shader_defs();
        defs.extend(defs_of([("DEFERRED_COMPUTE", compute)]));
        self.compose(DEFERRED.file, DEFERRED.source, defs)
    }

    /// Replaces the forward shader with a material's own WGSL (which may `#import`
    /// `penumbra::lights` and the other library modules). It must keep the forward shader's
    /// interface: `vs_main` and `fs_main`, bind groups 0–3 as in `forward.wgsl`, and the
    /// `ALPHA_MASK` / `ANALYSIS_OUTPUTS` defs (and, to use MSAA's alpha-to-coverage instead
    /// of the alpha test, `ALPHA_TO_COVERAGE`: no discard, alpha at location 0). The source is
    /// composed and validated for the opaque, masked and alpha-to-coverage PCF variants, with
    /// and without spot and point shadows, first; if that fails, the error is returned and the
    /// current shader stays in use.
    pub fn set_forward_source(&mut self, file: &str, source: &str) -> Result<(), ShaderError> {
        for (alpha_mask, samples) in [(false, 1), (true, 1), (true, 4)] {
            for local_shadows in [false, true] {
                let variant = ForwardVariant {
                    spot_shadows: local_shadows,
                    point_shadows: local_shadows,
                    ..ForwardVariant::for_settings(&Default::default(), alpha_mask).with_samples(samples)
                };
                self.compose(file, source, variant.shader_defs())?;
            }
        }
        self.forward_override = Some((file.to_owned(), source.to_owned()));
        self.forward_generation += 1;
        Ok(())
    }

    /// Goes back to the shipped forward shader.
    pub fn reset_forward_source(&mut self) {
        if self.forward_override.take().is_some() {
            self.forward_generation += 1;
        }
    }

    /// Whether a material's own forward shader replaced the shipped one
    /// ([`set_forward_source`](Self::set_forward_source)).
    pub fn forward_replaced(&self) -> bool {
        self.forward_override.is_some()
    }

    /// Changes every time the forward shader does.
    pub fn forward_generation(&self) -> u64 {
        self.forward_generation
    }

    /// The shipped forward shader's source (a starting point for a material's own shader).
    pub fn shipped_forward_source() -> &'static str {
        FORWARD.source
    }

    /// The shadow-caster shader (`vs_main` for both pipelines, `fs_masked` for alpha test);
    /// with `multiview`, the variant that renders several cascades in one pass (it reads
    /// `@builtin(view_index)`, so only a device with `MULTIVIEW` can build it).
    pub fn caster(&mut self, multiview: bool) -> Result<naga::Module, ShaderError> {
        self.compose(CASTER.file, CASTER.source, defs_of([("MULTIVIEW", multiview)]))
    }

    /// The partial shadow-layer clear (`vs_main`, no fragment stage).
    pub fn shadow_clear(&mut self) -> Result<naga::Module, ShaderError> {
        self.compose(SHADOW_CLEAR.file, SHADOW_CLEAR.source, HashMap::new())
    }

    /// The clipmap level shift (`vs_main`, `fs_main` writing depth).
    pub fn shadow_shift(&mut self) -> Result<naga::Module, ShaderError> {
        self.compose(SHADOW_SHIFT.file, SHADOW_SHIFT.source, HashMap::new())
    }

    /// The paged clipmap's allocation (`main`, one workgroup).
    pub fn pages_allocate(&mut self) -> Result<naga::Module, ShaderError> {
        self.compose(PAGES_ALLOCATE.file, PAGES_ALLOCATE.source, HashMap::new())
    }

    /// The paged clipmap's marking (`main`, a thread per pixel).
    pub fn pages_mark(&mut self, multisampled: bool) -> Result<naga::Module, ShaderError> {
        self.compose(
            PAGES_MARK.file,
            PAGES_MARK.source,
            defs_of([("MULTISAMPLED", multisampled)]),
        )
    }

    /// The paged clipmap's page drawing: with `cull`, the compute culling of casters per page
    /// (`cull`); without, the vertex stages of the tiles' clear (`clear_vs`) and of the
    /// casters (`caster_vs`).
    pub fn pages_render(&mut self, cull: bool) -> Result<naga::Module, ShaderError> {
        self.compose(PAGES_RENDER.file, PAGES_RENDER.source, defs_of([("CULL", cull)]))
    }

    /// The depth-bounds reduction (`main`) of the sample-distribution cascade fit, reading a
    /// single-sample or (`multisampled`) a multisampled camera depth.
    pub fn depth_bounds(&mut self, multisampled: bool) -> Result<naga::Module, ShaderError> {
        self.compose(
            DEPTH_BOUNDS.file,
            DEPTH_BOUNDS.source,
            defs_of([("MULTISAMPLED", multisampled)]),
        )
    }

    /// The compute skinning of bind-pose vertices into posed ones (`main`).
    pub fn skinning(&mut self) -> Result<naga::Module, ShaderError> {
        self.compose(SKINNING.file, SKINNING.source, defs_of([]))
    }

    /// The occlusion culling of the camera view's entries (`main`): the early phase, or the
    /// late phase's pyramid test (`late`).
    pub fn occlusion_cull(&mut self, late: bool) -> Result<naga::Module, ShaderError> {
        self.compose(OCCLUSION_CULL.file, OCCLUSION_CULL.source, defs_of([("LATE", late)]))
    }

    /// The GPU culling of shadow casters against their views' boxes (`main`).
    pub fn shadow_cull(&mut self) -> Result<naga::Module, ShaderError> {
        self.compose(SHADOW_CULL.file, SHADOW_CULL.source, defs_of([]))
    }

    /// One level of the occlusion culling's depth pyramid (`main`): level 0 from the camera
    /// depth (`first`), or a level from the one above it.
    pub fn occlusion_pyramid(&mut self, first: bool) -> Result<naga::Module, ShaderError> {
        self.compose(
            OCCLUSION_PYRAMID.file,
            OCCLUSION_PYRAMID.source,
            defs_of([("FIRST", first)]),
        )
    }

    /// The VSM moments shader (`resolve` and `blur`), for point lights' cubes (`point`) or
    /// spot lights' layers, writing `rgba32float` (`fp32`) or `rgba16float` covered moments.
    pub fn shadow_moments(&mut self, point: bool, fp32: bool) -> Result<naga::Module, ShaderError> {
        let defs = defs_of([("MOMENTS_POINT", point), ("MOMENTS_FP32", fp32)]);
        self.compose(SHADOW_MOMENTS.file, SHADOW_MOMENTS.source, defs)
    }

    /// The sun's moments shader (`resolve` and `blur`: EVSM2, EVSM4 or MSM from the depth
    /// cascades), writing moments in `format` (`Rgba32Float`, `Rgba16Unorm` or `Rgba16Float`).
    pub fn cascade_moments(&mut self, format: wgpu::TextureFormat) -> Result<naga::Module, ShaderError> {
        self.sun_moments(format, false)
    }

    /// The paged sun's moments bake (`page_bake`: the drawn pages' moments, blurred within
    /// each page), writing moments in `format` as [`cascade_moments`](Self::cascade_moments).
    pub fn page_moments(&mut self, format: wgpu::TextureFormat) -> Result<naga::Module, ShaderError> {
        self.sun_moments(format, true)
    }

    fn sun_moments(&mut self, format: wgpu::TextureFormat, pages: bool) -> Result<naga::Module, ShaderError> {
        let defs = defs_of([
            ("MOMENTS_RGBA32", format == wgpu::TextureFormat::Rgba32Float),
            ("MOMENTS_RGBA16_UNORM", format == wgpu::TextureFormat::Rgba16Unorm),
            ("PAGES", pages),
        ]);
        self.compose(CASCADE_MOMENTS.file, CASCADE_MOMENTS.source, defs)
    }

    /// The depth-prepass shader (`vs_main` for both pipelines, `fs_masked` for alpha test).
    pub fn prepass(&mut self) -> Result<naga::Module, ShaderError> {
        self.compose(PREPASS.file, PREPASS.source, HashMap::new())
    }

    /// The compute visibility resolve (`main`), with the filters of `variant`, reading a
    /// single-sample depth and normals.
    pub fn resolve(&mut self, variant: ForwardVariant) -> Result<naga::Module, ShaderError> {
        self.resolve_multisampled(variant, 1)
    }

    /// [`resolve`](Self::resolve) reading depth and normals of `samples` samples per pixel
    /// (1, 2 or 4; MSAA): each pixel from its sample 0.
    pub fn resolve_multisampled(&mut self, variant: ForwardVariant, samples: u32) -> Result<naga::Module, ShaderError> {
        let mut defs = variant.shader_defs();
        defs.extend(defs_of([("MULTISAMPLED", samples > 1), ("MSAA_X2", samples == 2)]));
        self.compose(RESOLVE.file, RESOLVE.source, defs)
    }

    /// The shadow-probe compute shader (`main`), with the filter of `variant`.
    pub fn probe(&mut self, variant: ForwardVariant) -> Result<naga::Module, ShaderError> {
        self.compose(PROBE.file, PROBE.source, variant.shader_defs())
    }
}

/// The boolean shader defs of `flags` that are on.
fn defs_of<const N: usize>(flags: [(&str, bool); N]) -> HashMap<String, naga_oil::compose::ShaderDefValue> {
    flags
        .into_iter()
        .filter(|(_, on)| *on)
        .map(|(name, _)| (name.to_string(), naga_oil::compose::ShaderDefValue::Bool(true)))
        .collect()
}

/// What shaders may use: naga's defaults, `@builtin(view_index)` (only the multiview
/// caster reads it; wgpu refuses that module on a device without `MULTIVIEW`), 16-bit
/// unorm storage textures (only the 16-bit MSM bake writes them, on a device with
/// `TEXTURE_FORMAT_16BIT_NORM`) and clip distances (only the paged clipmap's caster writes
/// them, on a device with `CLIP_DISTANCES`).
fn capabilities() -> Capabilities {
    Capabilities::default()
        | Capabilities::MULTIVIEW
        | Capabilities::STORAGE_TEXTURE_16BIT_NORM_FORMATS
        | Capabilities::CLIP_DISTANCES
}

/// Runs naga's validator over a composed module.
pub fn validate(file: &str, module: &naga::Module) -> Result<naga::valid::ModuleInfo, ShaderError> {
    Validator::new(ValidationFlags::all(), capabilities())
        .validate(module)
        .map_err(|e| ShaderError::Validate {
            file: file.to_string(),
            message: format!("{:?}", e.into_inner()),
        })
}
