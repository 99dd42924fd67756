//! Relief-texture impostors: the second representation of a big scan's part (the relief-texture
//! paper's), drawn in place of its triangles where the chooser (`phantogram-detail`) says so.
//!
//! An impostor is the part's box seen from its six faces, baked once by this renderer: per face,
//! an orthographic view looking inwards, `texels × texels`, holding for each texel the first
//! surface's depth along the face's axis and its material as the scene shader computes it (base
//! colour, metallic, normal, roughness, occlusion; not emission, not transparency). Drawn, the
//! box's front faces cast each eye's own ray through the six depth maps (`fs_impostor` in
//! `scene.wgsl`): the first point at or behind the first surface in all six views is the surface
//! the polygons would show, up to the maps' resolution; its material comes from the view that
//! sees it, it is lit by the same `shade` as polygons and its depth is written, so impostors and
//! polygons hide each other correctly in each eye.
//!
//! What the six views cannot see — a cavity hidden from all six directions — is filled (the
//! shape drawn is the part's six-sided relief hull); a part's parts hidden from the view that
//! matches best take that view's material. Both are below a texel where the chooser uses an
//! impostor (its error is [`ImpostorBox::error_m`]).
//!
//! Frames: the box is in the model's (mesh) coordinates, the device frame, metres. The maps'
//! convention is documented once, in `scene.wgsl` above `GBufferOut`; [`ImpostorBox::face_view`]
//! is its Rust half. **Panics**: none; GPU failures come back as [`crate::RenderError`].

use glam::{Mat4, Vec3, Vec4};

/// The level in [`crate::FrameInput::levels`] that draws a primitive's impostor, where one was
/// baked ([`crate::Renderer::bake_impostors`]); without one it draws the coarsest level.
pub use phantogram_assets::model::IMPOSTOR_LEVEL;

/// Formats of the three maps: base colour and metallic; octahedral normal, roughness (−1 for
/// unlit) and occlusion; depth along the face's axis (2 where the texel sees nothing) at the
/// texel's centre and, conservatively, around it (`impostor_dilate.wgsl`). The bake renders the
/// depth into a transient map of the first format, then makes the kept one.
///
/// The depths are f32 values kept as their bits in 32-bit unsigned integers (the shaders
/// `bitcast` them; only `textureLoad` reads them, so nothing is filtered or blended): OpenGL ES
/// 3, Android's fallback, renders to 32-bit integer formats everywhere but to 32-bit float ones
/// only with `EXT_color_buffer_float` — which wgpu also fails to see on desktop OpenGL's core
/// profiles — and an `R32Float` target there made the impostors' pipelines fail, so big scans
/// were drawn from polygons only.
pub(crate) const COLOUR_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::Rgba8UnormSrgb;
pub(crate) const NORMAL_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::Rgba16Float;
pub(crate) const RAW_DEPTH_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::R32Uint;
pub(crate) const DEPTH_MAP_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::Rg32Uint;
/// The WGSL of the depth map's second pass, validated by naga in the tests.
pub const IMPOSTOR_DILATE_WGSL: &str = include_str!("../../../shaders/impostor_dilate.wgsl");
/// Bytes per texel of the three maps kept.
pub const BYTES_PER_TEXEL: u64 = 4 + 8 + 8;
/// What an empty texel's depth holds: beyond the box, so no point is behind it.
pub(crate) const EMPTY_DEPTH: f32 = 2.0;

/// GPU memory of an impostor's three maps at `texels` per side, bytes: six views, on OpenGL (ES)
/// (`opengl`) a seventh, spare layer ([`phantogram_assets::budget::array_layers`]).
pub fn maps_bytes(texels: u32, opengl: bool) -> u64 {
    let layers = phantogram_assets::budget::array_layers(texels, texels, 6, opengl);
    u64::from(layers) * u64::from(texels) * u64::from(texels) * BYTES_PER_TEXEL
}

/// An impostor's box and resolution (GPU-free).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ImpostorBox {
    /// Corners in mesh coordinates, metres.
    pub lo: Vec3,
    pub hi: Vec3,
    /// Texels along each side of each face's map.
    pub texels: u32,
}

impl ImpostorBox {
    /// The box around `points` with one texel of margin on every side (so that no surface lies
    /// on the box, where the maps' nearest texel would clip it, and a flat part still has
    /// depth), `texels` per side (at least 2). `None` without points or with a non-finite one.
    pub fn around(points: impl IntoIterator<Item = Vec3>, texels: u32) -> Option<Self> {
        let mut lo = Vec3::splat(f32::INFINITY);
        let mut hi = Vec3::splat(f32::NEG_INFINITY);
        let mut any = false;
        for p in points {
            if !p.is_finite() {
                return None;
            }
            lo = lo.min(p);
            hi = hi.max(p);
            any = true;
        }
        if !any {
            return None;
        }
        let texels = texels.max(2);
        let largest = (hi - lo).max_element().max(1e-6);
        let margin = largest / (texels as f32 - 2.0).max(1.0);
        Some(Self {
            lo: lo - Vec3::splat(margin),
            hi: hi + Vec3::splat(margin),
            texels,
        })
    }

    /// The box's size along each axis, metres.
    pub fn extent_m(&self) -> Vec3 {
        self.hi - self.lo
    }

    /// A texel's size along each axis (on the faces across that axis), metres.
    pub fn texel_m(&self) -> Vec3 {
        self.extent_m() / self.texels as f32
    }

    /// A bound on how far a surface point drawn by the impostor can lie from the true surface,
    /// the geometric error the chooser compares with its polygon levels'. Along the axis of the
    /// view that bounds the hull there (the one most facing the surface, within 54.7° of its
    /// normal): the texel the hull is grown by, so that thin shells are found, and the
    /// conservative depth's reach — the nearest of the texel and its neighbours, up to one and a
    /// half texels away on a slope of at most √2; across it, half a texel (the maps are read at
    /// the nearest texel). The worst view's. Measured errors are far smaller (the tests find
    /// surface points within a pixel of the polygons' at texels of half a pixel).
    pub fn error_m(&self) -> f32 {
        let t = self.texel_m();
        let along = 1.0 + 1.5 * std::f32::consts::SQRT_2;
        let mut worst = 0.0f32;
        for a in 0..3 {
            let (u, v) = ((a + 1) % 3, (a + 2) % 3);
            worst = worst.max(((along * t[a]).powi(2) + 0.25 * (t[u] * t[u] + t[v] * t[v])).sqrt());
        }
        worst
    }

    /// GPU memory of the three maps, bytes, on a backend other than OpenGL (ES).
    pub fn bytes(&self) -> u64 {
        self.bytes_on(false)
    }

    /// GPU memory of the three maps, bytes, on OpenGL (ES) (`opengl`) or another backend:
    /// [`maps_bytes`].
    pub fn bytes_on(&self, opengl: bool) -> u64 {
        maps_bytes(self.texels, opengl)
    }

    /// Box coordinates q = (p − lo) / extent of mesh point `p` (0 to 1 inside).
    pub fn to_box(&self, p: Vec3) -> Vec3 {
        (p - self.lo) / self.extent_m()
    }

    /// Face `face`'s view (0 to 5; face 2a looks from the +a side, 2a+1 from the −a side): mesh
    /// coordinates → clip space with x = 1 − 2 q(a+1) from the + side, 2 q(a+1) − 1 from the −
    /// side, y = 1 − 2 q(a+2) (so the map's column and row are 1 − q(a+1) or q(a+1), and
    /// q(a+2), times `texels`) and z the depth from that side, 1 − q(a) or q(a); q(i) is the
    /// box coordinate along axis i mod 3 ([`Self::to_box`]).
    pub fn face_view(&self, face: usize) -> Mat4 {
        let a = (face / 2).min(2);
        let (u, v) = ((a + 1) % 3, (a + 2) % 3);
        let e = self.extent_m();
        let axis = |i: usize, scale: f32| {
            let mut r = Vec4::ZERO;
            r[i] = scale / e[i];
            r
        };
        // Seen from the + side, (u, v) with y up is a mirror image: x runs the other way there,
        // so that front faces are counter-clockwise in every view as in the eyes' (the bake
        // lights double-sided surfaces from the side facing the view, as the scene pass does).
        let row_x = if face.is_multiple_of(2) {
            let mut r = axis(u, -2.0);
            r.w = 2.0 * self.lo[u] / e[u] + 1.0;
            r
        } else {
            let mut r = axis(u, 2.0);
            r.w = -2.0 * self.lo[u] / e[u] - 1.0;
            r
        };
        let mut row_y = axis(v, -2.0);
        row_y.w = 2.0 * self.lo[v] / e[v] + 1.0;
        let row_z = if face.is_multiple_of(2) {
            let mut r = axis(a, -1.0);
            r.w = self.hi[a] / e[a];
            r
        } else {
            let mut r = axis(a, 1.0);
            r.w = -self.lo[a] / e[a];
            r
        };
        Mat4::from_cols(row_x, row_y, row_z, Vec4::W).transpose()
    }
}

/// The pipelines impostors are baked and drawn with, made with the first bake.
pub(crate) struct ImpostorPipelines {
    bake: wgpu::RenderPipeline,
    dilate: wgpu::RenderPipeline,
    dilate_layout: wgpu::BindGroupLayout,
    draw: wgpu::RenderPipeline,
    layout: wgpu::BindGroupLayout,
    /// Group 1 of the draw: the material's slot, unused by `fs_impostor`.
    empty: wgpu::BindGroup,
    /// One eye block per face (only the view matters), written before each part's bake.
    face_buffers: Vec<wgpu::Buffer>,
    face_binds: Vec<wgpu::BindGroup>,
}

/// One primitive's baked impostor.
pub(crate) struct GpuImpostor {
    pub(crate) bind: wgpu::BindGroup,
    pub(crate) bounds: ImpostorBox,
    /// The coarsest polygon level as exact as the impostor: what casts its shadow (the shadow
    /// pass draws polygons; a coarser caster would shadow the impostor's own surface).
    pub(crate) shadow_level: u8,
    // Kept alive for the bind group.
    _uniform: wgpu::Buffer,
    _maps: [wgpu::Texture; 3],
}

/// Layer `face` of a six-layer map, as a 2D view (a render target).
fn layer_view(t: &wgpu::Texture, face: u32) -> wgpu::TextureView {
    t.create_view(&wgpu::TextureViewDescriptor {
        dimension: Some(wgpu::TextureViewDimension::D2),
        base_array_layer: face,
        array_layer_count: Some(1),
        ..Default::default()
    })
}

/// A map read by `textureLoad` only, at `binding`: a six-layer array (`D2Array`) when drawn, one
/// layer (`D2`) in the bake's depth pass.
fn map_entry(
    binding: u32,
    sample_type: wgpu::TextureSampleType,
    view_dimension: wgpu::TextureViewDimension,
) -> wgpu::BindGroupLayoutEntry {
    wgpu::BindGroupLayoutEntry {
        binding,
        visibility: wgpu::ShaderStages::FRAGMENT,
        ty: wgpu::BindingType::Texture {
            sample_type,
            view_dimension,
            multisampled: false,
        },
        count: None,
    }
}

const FLOAT: wgpu::TextureSampleType = wgpu::TextureSampleType::Float { filterable: false };

impl crate::Renderer {
    /// Makes the impostors' pipelines if they are not made yet.
    fn make_impostor_pipelines(&mut self) {
        if self.impostor_pipelines.is_none() {
            let device = &self.gpu.device;
            let layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
                label: Some("impostor"),
                entries: &[
                    crate::uniform_entry(0, wgpu::ShaderStages::VERTEX_FRAGMENT),
                    map_entry(1, FLOAT, wgpu::TextureViewDimension::D2Array),
                    map_entry(2, FLOAT, wgpu::TextureViewDimension::D2Array),
                    map_entry(3, wgpu::TextureSampleType::Uint, wgpu::TextureViewDimension::D2Array),
                ],
            });
            let empty_layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
                label: Some("impostor (no material)"),
                entries: &[],
            });
            let empty = device.create_bind_group(&wgpu::BindGroupDescriptor {
                label: Some("impostor (no material)"),
                layout: &empty_layout,
                entries: &[],
            });
            let draw_layout = device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
                label: Some("impostor"),
                bind_group_layouts: &[Some(&self.eye_layout), Some(&empty_layout), Some(&layout)],
                immediate_size: 0,
            });
            let module = &self.scene.module;
            let draw = device.create_render_pipeline(&wgpu::RenderPipelineDescriptor {
                label: Some("impostor"),
                layout: Some(&draw_layout),
                vertex: wgpu::VertexState {
                    module,
                    entry_point: Some("vs_impostor"),
                    compilation_options: Default::default(),
                    buffers: &[Some(crate::fade_buffer_layout(&crate::FADE_ATTRIBUTES))],
                },
                // Back faces are discarded in the shader by the ray's direction, whatever the
                // projection's handedness.
                primitive: wgpu::PrimitiveState::default(),
                depth_stencil: Some(wgpu::DepthStencilState {
                    format: crate::DEPTH_FORMAT,
                    depth_write_enabled: Some(true),
                    depth_compare: Some(wgpu::CompareFunction::Greater),
                    stencil: Default::default(),
                    bias: Default::default(),
                }),
                multisample: Default::default(),
                fragment: Some(wgpu::FragmentState {
                    module,
                    entry_point: Some("fs_impostor"),
                    compilation_options: Default::default(),
                    targets: &[Some(crate::HDR_FORMAT.into())],
                }),
                multiview_mask: None,
                cache: None,
            });
            let vertex_attributes = wgpu::vertex_attr_array![
                0 => Float32x3, 1 => Float32x3, 2 => Float32x4, 3 => Float32x4, 4 => Float32x4, 5 => Float32x2
            ];
            let bake = device.create_render_pipeline(&wgpu::RenderPipelineDescriptor {
                label: Some("impostor bake"),
                layout: Some(&self.scene.layout),
                vertex: wgpu::VertexState {
                    module,
                    entry_point: Some("vs_main"),
                    compilation_options: Default::default(),
                    buffers: &[Some(crate::vertex_buffer(&vertex_attributes))],
                },
                // Both faces: open and double-sided surfaces are seen from either side.
                primitive: wgpu::PrimitiveState::default(),
                depth_stencil: Some(wgpu::DepthStencilState {
                    format: crate::DEPTH_FORMAT,
                    depth_write_enabled: Some(true),
                    depth_compare: Some(wgpu::CompareFunction::Less),
                    stencil: Default::default(),
                    bias: Default::default(),
                }),
                multisample: Default::default(),
                // The general shader (every slot sampled; missing ones hold neutral defaults).
                fragment: Some(wgpu::FragmentState {
                    module,
                    entry_point: Some("fs_gbuffer"),
                    compilation_options: Default::default(),
                    targets: &[
                        Some(COLOUR_FORMAT.into()),
                        Some(NORMAL_FORMAT.into()),
                        Some(RAW_DEPTH_FORMAT.into()),
                    ],
                }),
                multiview_mask: None,
                cache: None,
            });
            let dilate_module = device.create_shader_module(wgpu::ShaderModuleDescriptor {
                label: Some("impostor_dilate.wgsl"),
                source: wgpu::ShaderSource::Wgsl(IMPOSTOR_DILATE_WGSL.into()),
            });
            let dilate_layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
                label: Some("impostor depth (raw)"),
                entries: &[map_entry(
                    0,
                    wgpu::TextureSampleType::Uint,
                    wgpu::TextureViewDimension::D2,
                )],
            });
            let dilate_pipeline_layout = device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
                label: Some("impostor depth (conservative)"),
                bind_group_layouts: &[Some(&dilate_layout)],
                immediate_size: 0,
            });
            let dilate = device.create_render_pipeline(&wgpu::RenderPipelineDescriptor {
                label: Some("impostor depth (conservative)"),
                layout: Some(&dilate_pipeline_layout),
                vertex: wgpu::VertexState {
                    module: &dilate_module,
                    entry_point: Some("vs_main"),
                    compilation_options: Default::default(),
                    buffers: &[],
                },
                primitive: wgpu::PrimitiveState::default(),
                depth_stencil: None,
                multisample: Default::default(),
                fragment: Some(wgpu::FragmentState {
                    module: &dilate_module,
                    entry_point: Some("fs_main"),
                    compilation_options: Default::default(),
                    targets: &[Some(DEPTH_MAP_FORMAT.into())],
                }),
                multiview_mask: None,
                cache: None,
            });
            let face_buffers: Vec<wgpu::Buffer> = (0..6)
                .map(|_| crate::eye_block_buffer(device, "impostor face"))
                .collect();
            let face_binds = face_buffers
                .iter()
                .map(|b| crate::eye_bind_group(device, &self.eye_layout, b, &self.eye_views(), 0, &self.ibl))
                .collect();
            self.impostor_pipelines = Some(ImpostorPipelines {
                bake,
                dilate,
                dilate_layout,
                draw,
                layout,
                empty,
                face_buffers,
                face_binds,
            });
        }
    }

    /// Bakes an impostor for each `(primitive, box)` of the model set (primitives by index in the
    /// [`Model`](phantogram_assets::model::Model) it was set from; boxes from
    /// [`ImpostorBox::around`] its vertices), replacing any baked before for it. Blended
    /// primitives and indices past the model are skipped. Returns the bytes of GPU memory the
    /// maps of those baked take. The impostors are dropped with the model
    /// ([`crate::Renderer::set_model`], [`crate::Renderer::update_vertices`]).
    pub fn bake_impostors(&mut self, boxes: &[(usize, ImpostorBox)]) -> Result<u64, crate::RenderError> {
        let device = self.gpu.device.clone();
        crate::checked(&device, "the impostors' pipelines", || self.make_impostor_pipelines())?;
        let mut bytes = 0;
        for &(source, bounds) in boxes {
            let blended = self
                .model
                .primitives
                .iter()
                .filter(|p| p.source == source)
                .any(|p| self.model.materials[p.material].variant.blend);
            let drawn = self.model.primitives.iter().any(|p| p.source == source);
            if blended || !drawn || !bounds.lo.is_finite() || !bounds.hi.is_finite() {
                continue;
            }
            let Some(baked) = crate::checked(&device, "an impostor", || self.bake_one(source, bounds))? else {
                continue;
            };
            bytes += baked.bounds.bytes_on(self.gpu.is_opengl());
            if self.model.impostors.len() <= source {
                self.model.impostors.resize_with(source + 1, || None);
            }
            self.model.impostors[source] = Some(baked);
        }
        Ok(bytes)
    }

    /// Whether primitive `source` of the model set has an impostor.
    pub fn has_impostor(&self, source: usize) -> bool {
        self.model.impostors.get(source).is_some_and(Option::is_some)
    }

    fn bake_one(&mut self, source: usize, bounds: ImpostorBox) -> Option<GpuImpostor> {
        let texels = bounds.texels.min(self.gpu.device.limits().max_texture_dimension_2d);
        let bounds = ImpostorBox { texels, ..bounds };
        let device = self.gpu.device.clone();
        let queue = self.gpu.queue.clone();
        // Six views, read as an array (a seventh layer on OpenGL: `Gpu::array_layers`).
        let layers = self.gpu.array_layers(texels, texels, 6);
        let map = |label, format, layers| {
            device.create_texture(&wgpu::TextureDescriptor {
                label: Some(label),
                size: wgpu::Extent3d {
                    width: texels,
                    height: texels,
                    depth_or_array_layers: layers,
                },
                mip_level_count: 1,
                sample_count: 1,
                dimension: wgpu::TextureDimension::D2,
                format,
                usage: wgpu::TextureUsages::RENDER_ATTACHMENT | wgpu::TextureUsages::TEXTURE_BINDING,
                view_formats: &[],
            })
        };
        let maps = [
            map("impostor colour", COLOUR_FORMAT, layers),
            map("impostor normal", NORMAL_FORMAT, layers),
            map("impostor depth", DEPTH_MAP_FORMAT, layers),
        ];
        // One face's raw depth at a time, a plain 2D texture: each face's bake is followed by its
        // depth pass. (OpenGL cannot read one layer of an array as a 2D texture: its views keep
        // the texture's own target, and such a read gave zeros.)
        let raw_depth = map("impostor depth (raw)", RAW_DEPTH_FORMAT, 1).create_view(&Default::default());
        let depth = device
            .create_texture(&wgpu::TextureDescriptor {
                label: Some("impostor bake depth"),
                size: wgpu::Extent3d {
                    width: texels,
                    height: texels,
                    depth_or_array_layers: 1,
                },
                mip_level_count: 1,
                sample_count: 1,
                dimension: wgpu::TextureDimension::D2,
                format: crate::DEPTH_FORMAT,
                usage: wgpu::TextureUsages::RENDER_ATTACHMENT,
                view_formats: &[],
            })
            .create_view(&Default::default());
        // Made by `bake_impostors` before.
        let pipelines = self.impostor_pipelines.as_ref()?;
        for (face, buffer) in pipelines.face_buffers.iter().enumerate() {
            let uniform = crate::EyeUniform {
                view_proj: bounds.face_view(face).to_cols_array_2d(),
                ..bytemuck::Zeroable::zeroed()
            };
            queue.write_buffer(buffer, 0, bytemuck::bytes_of(&uniform));
        }
        let raw_bind = device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("impostor depth (raw)"),
            layout: &pipelines.dilate_layout,
            entries: &[wgpu::BindGroupEntry {
                binding: 0,
                resource: wgpu::BindingResource::TextureView(&raw_depth),
            }],
        });
        let mut encoder = device.create_command_encoder(&Default::default());
        for face in 0..6u32 {
            let views = [
                layer_view(&maps[0], face),
                layer_view(&maps[1], face),
                raw_depth.clone(),
            ];
            let clear = |view, colour| {
                Some(wgpu::RenderPassColorAttachment {
                    view,
                    depth_slice: None,
                    resolve_target: None,
                    ops: wgpu::Operations {
                        load: wgpu::LoadOp::Clear(colour),
                        store: wgpu::StoreOp::Store,
                    },
                })
            };
            let mut pass = encoder.begin_render_pass(&wgpu::RenderPassDescriptor {
                label: Some("impostor bake"),
                color_attachments: &[
                    clear(&views[0], wgpu::Color::TRANSPARENT),
                    clear(
                        &views[1],
                        wgpu::Color {
                            r: 0.0,
                            g: 0.0,
                            b: 1.0,
                            a: 1.0,
                        },
                    ),
                    clear(
                        &views[2],
                        // The integer target is cleared to the value's bits (exact in f64).
                        wgpu::Color {
                            r: f64::from(EMPTY_DEPTH.to_bits()),
                            g: 0.0,
                            b: 0.0,
                            a: 1.0,
                        },
                    ),
                ],
                depth_stencil_attachment: Some(wgpu::RenderPassDepthStencilAttachment {
                    view: &depth,
                    depth_ops: Some(wgpu::Operations {
                        load: wgpu::LoadOp::Clear(1.0),
                        store: wgpu::StoreOp::Discard,
                    }),
                    stencil_ops: None,
                }),
                ..Default::default()
            });
            pass.set_pipeline(&pipelines.bake);
            pass.set_bind_group(0, &pipelines.face_binds[face as usize], &[]);
            for p in self.model.primitives.iter().filter(|p| p.source == source) {
                pass.set_bind_group(1, &self.model.materials[p.material].bind, &[]);
                p.draw(&mut pass, &[]);
            }
            drop(pass);
            crate::pipelines::draw_fullscreen(
                &mut encoder,
                "impostor depth (conservative)",
                &layer_view(&maps[2], face),
                &pipelines.dilate,
                &raw_bind,
                None,
            );
        }
        queue.submit([encoder.finish()]);
        let uniform = device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("impostor"),
            size: 32,
            usage: wgpu::BufferUsages::UNIFORM | wgpu::BufferUsages::COPY_DST,
            mapped_at_creation: false,
        });
        let values: [f32; 8] = [
            bounds.lo.x,
            bounds.lo.y,
            bounds.lo.z,
            texels as f32,
            bounds.hi.x,
            bounds.hi.y,
            bounds.hi.z,
            0.0,
        ];
        queue.write_buffer(&uniform, 0, bytemuck::cast_slice(&values));
        let array_view = |t: &wgpu::Texture| {
            t.create_view(&wgpu::TextureViewDescriptor {
                dimension: Some(wgpu::TextureViewDimension::D2Array),
                ..Default::default()
            })
        };
        let views = [array_view(&maps[0]), array_view(&maps[1]), array_view(&maps[2])];
        let bind = device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("impostor"),
            layout: &pipelines.layout,
            entries: &[
                wgpu::BindGroupEntry {
                    binding: 0,
                    resource: uniform.as_entire_binding(),
                },
                wgpu::BindGroupEntry {
                    binding: 1,
                    resource: wgpu::BindingResource::TextureView(&views[0]),
                },
                wgpu::BindGroupEntry {
                    binding: 2,
                    resource: wgpu::BindingResource::TextureView(&views[1]),
                },
                wgpu::BindGroupEntry {
                    binding: 3,
                    resource: wgpu::BindingResource::TextureView(&views[2]),
                },
            ],
        });
        let error_m = bounds.error_m();
        let shadow_level = self
            .model
            .primitives
            .iter()
            .filter(|p| p.source == source)
            .map(|p| p.level_errors_m.iter().rposition(|&e| e <= error_m).unwrap_or(0))
            .min()
            .unwrap_or(0)
            .min(usize::from(IMPOSTOR_LEVEL - 1)) as u8;
        Some(GpuImpostor {
            bind,
            bounds,
            shadow_level,
            _uniform: uniform,
            _maps: maps,
        })
    }

    /// Draws `impostor` into the eye pass (eye bind group set) as instance `instance` of the
    /// cross-fades' buffer (0: not fading).
    pub(crate) fn draw_impostor(&self, pass: &mut wgpu::RenderPass<'_>, impostor: &GpuImpostor, instance: u32) {
        let Some(pipelines) = self.impostor_pipelines.as_ref() else {
            return;
        };
        pass.set_pipeline(&pipelines.draw);
        pass.set_bind_group(1, &pipelines.empty, &[]);
        pass.set_bind_group(2, &impostor.bind, &[]);
        pass.set_vertex_buffer(0, self.fade_buffer.slice(..));
        pass.draw(0..36, instance..instance + 1);
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn unit_box() -> ImpostorBox {
        ImpostorBox {
            lo: Vec3::new(-0.1, 0.2, 0.0),
            hi: Vec3::new(0.3, 0.4, 0.05),
            texels: 64,
        }
    }

    /// The face views follow the convention `fs_impostor` reads the maps by, and none is a
    /// mirror image (front faces stay counter-clockwise).
    #[test]
    fn face_views_map_the_box_as_the_shader_reads_it() {
        let b = unit_box();
        for face in 0..6usize {
            // A triangle facing the view (normal towards its side) is counter-clockwise in
            // clip space.
            let a = face / 2;
            let toward = if face.is_multiple_of(2) { 1.0 } else { -1.0 };
            let (u, v) = ((a + 1) % 3, (a + 2) % 3);
            let mut p = [b.lo + b.extent_m() * 0.5; 3];
            p[1][u] += 0.01;
            p[2][v] += 0.01;
            let mut n = Vec3::ZERO;
            n[a] = toward;
            if (p[1] - p[0]).cross(p[2] - p[0]).dot(n) < 0.0 {
                p.swap(1, 2);
            }
            let c = p.map(|q| (b.face_view(face) * q.extend(1.0)).truncate());
            let signed_area = (c[1] - c[0]).truncate().perp_dot((c[2] - c[0]).truncate());
            assert!(signed_area > 0.0, "face {face} mirrors");
        }
        for face in 0..6usize {
            let a = face / 2;
            let (u, v) = ((a + 1) % 3, (a + 2) % 3);
            let m = b.face_view(face);
            for q in [
                Vec3::ZERO,
                Vec3::ONE,
                Vec3::new(0.25, 0.5, 0.75),
                Vec3::new(0.9, 0.1, 0.3),
            ] {
                let p = b.lo + q * b.extent_m();
                let c = m * p.extend(1.0);
                assert!((c.w - 1.0).abs() < 1e-6, "orthographic");
                let column = if face.is_multiple_of(2) { 1.0 - q[u] } else { q[u] };
                assert!((c.x - (2.0 * column - 1.0)).abs() < 1e-5, "face {face} x at {q}");
                assert!((c.y - (1.0 - 2.0 * q[v])).abs() < 1e-5, "face {face} y at {q}");
                let depth = if face.is_multiple_of(2) { 1.0 - q[a] } else { q[a] };
                assert!((c.z - depth).abs() < 1e-5, "face {face} depth at {q}: {}", c.z);
                assert!((b.to_box(p) - q).abs().max_element() < 1e-5);
            }
        }
    }

    #[test]
    fn the_box_holds_its_points_with_a_texel_to_spare() {
        let points = [Vec3::new(0.0, 0.0, 0.0), Vec3::new(0.1, 0.02, 0.0)];
        let b = ImpostorBox::around(points, 32).expect("a box");
        let t = b.texel_m();
        for p in points {
            let q = b.to_box(p);
            assert!(q.min_element() > 0.0 && q.max_element() < 1.0, "{q}");
            for a in 0..3 {
                assert!(
                    p[a] - b.lo[a] >= t[a] * 0.99 && b.hi[a] - p[a] >= t[a] * 0.99,
                    "axis {a}"
                );
            }
        }
        // A flat part still has depth.
        assert!(b.extent_m().z > 0.0);
        assert!(b.error_m() > 0.0 && b.error_m() < 0.1 / 32.0 * 3.5);
        assert_eq!(b.bytes(), 6 * 32 * 32 * BYTES_PER_TEXEL);
        assert!(ImpostorBox::around([], 32).is_none());
        assert!(ImpostorBox::around([Vec3::NAN], 32).is_none());
    }
}
