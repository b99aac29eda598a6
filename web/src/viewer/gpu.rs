//! The viewer's wgpu renderer on the page's canvas, on the browser's WebGPU or on WebGL2
//! (wgpu's GL backend, with the same WGSL shader, which wgpu translates): one pipeline for
//! triangles (the figure, lit by normal, and the shadows, blended), one for lines (grid and
//! paths), one uniform (the camera and the light). It owns its own GPU device: the models run
//! in a worker, and a device cannot cross threads. Errors the device reports later (a lost
//! device, a failed validation) are kept and returned by the next [`GpuRenderer::draw`], so
//! the viewer can fall to another renderer instead of the page panicking.

use super::scene::{
    shadow_triangles, vertex_bytes, Frame, Vertex, AMBIENT, BACKGROUND, DIFFUSE, LIGHT, SKY,
    VERTEX_BYTES,
};
use std::sync::{Arc, Mutex};
use wasm_bindgen::closure::Closure;
use wasm_bindgen::JsCast;

const DEPTH_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::Depth32Float;
/// The uniform: a 4×4 matrix and two vec4s.
const UNIFORM_BYTES: u64 = 96;

/// Which of the browser's GPU interfaces draws.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum GpuApi {
    WebGpu,
    WebGl2,
}

impl GpuApi {
    fn name(self) -> &'static str {
        match self {
            GpuApi::WebGpu => "WebGPU",
            GpuApi::WebGl2 => "WebGL2",
        }
    }
}

/// The wgpu renderer of one canvas.
pub struct GpuRenderer {
    // The instance and adapter must outlive the device: the browser loses a device whose
    // instance is gone.
    _instance: wgpu::Instance,
    _adapter: wgpu::Adapter,
    surface: wgpu::Surface<'static>,
    device: wgpu::Device,
    queue: wgpu::Queue,
    config: wgpu::SurfaceConfiguration,
    triangles: wgpu::RenderPipeline,
    lines: wgpu::RenderPipeline,
    camera: wgpu::Buffer,
    bind_group: wgpu::BindGroup,
    depth: wgpu::TextureView,
    /// 1 when the canvas format is sRGB (the shader then decodes the sRGB colours).
    srgb: f32,
    /// Vertex buffers reused across frames (lines, shadows, body), grown when a frame needs
    /// more.
    vertices: [Option<(wgpu::Buffer, u64)>; 3],
    /// The first error the device reported after creation (lost, out of memory, invalid).
    failure: Arc<Mutex<Option<String>>>,
}

fn depth_view(device: &wgpu::Device, width: u32, height: u32) -> wgpu::TextureView {
    device
        .create_texture(&wgpu::TextureDescriptor {
            label: Some("depth"),
            size: wgpu::Extent3d {
                width,
                height,
                depth_or_array_layers: 1,
            },
            mip_level_count: 1,
            sample_count: 1,
            dimension: wgpu::TextureDimension::D2,
            format: DEPTH_FORMAT,
            usage: wgpu::TextureUsages::RENDER_ATTACHMENT,
            view_formats: &[],
        })
        .create_view(&wgpu::TextureViewDescriptor::default())
}

/// Keeps the first message, so the cause is reported rather than its consequences.
fn keep_first(slot: &Mutex<Option<String>>, message: String) {
    if let Ok(mut s) = slot.lock() {
        s.get_or_insert(message);
    }
}

impl GpuRenderer {
    /// A renderer on `canvas` (sized in device pixels by the caller) through `api`. A canvas
    /// takes one kind of context for good: after a failure here, use a fresh canvas.
    pub async fn new(
        canvas: web_sys::HtmlCanvasElement,
        api: GpuApi,
    ) -> Result<GpuRenderer, String> {
        let (width, height) = (canvas.width().max(1), canvas.height().max(1));
        if api == GpuApi::WebGpu && !crate::browser::has_webgpu() {
            return Err("this browser offers no WebGPU".into());
        }
        let instance = wgpu::Instance::new(wgpu::InstanceDescriptor {
            backends: match api {
                GpuApi::WebGpu => wgpu::Backends::BROWSER_WEBGPU,
                GpuApi::WebGl2 => wgpu::Backends::GL,
            },
            ..wgpu::InstanceDescriptor::new_without_display_handle()
        });
        let name = api.name();
        let failure = Arc::new(Mutex::new(None));
        if api == GpuApi::WebGl2 {
            // wgpu does not report a lost WebGL context as a lost device; the canvas does.
            let lost = failure.clone();
            let listener = Closure::<dyn FnMut()>::new(move || {
                keep_first(&lost, "the WebGL2 context was lost".into());
            });
            canvas
                .add_event_listener_with_callback(
                    "webglcontextlost",
                    listener.as_ref().unchecked_ref(),
                )
                .map_err(|e| format!("cannot watch the canvas's WebGL2 context: {e:?}"))?;
            // Lives as long as the canvas, which the next renderer replaces.
            listener.forget();
        }
        let surface = instance
            .create_surface(wgpu::SurfaceTarget::Canvas(canvas))
            .map_err(|e| format!("the canvas cannot show {name}: {e}"))?;
        let adapter = instance
            .request_adapter(&wgpu::RequestAdapterOptions {
                compatible_surface: Some(&surface),
                ..Default::default()
            })
            .await
            .map_err(|e| format!("no {name} adapter: {e}"))?;
        // WebGL2's limits are below WebGPU's defaults; the viewer needs little of either.
        let (device, queue) = adapter
            .request_device(&wgpu::DeviceDescriptor {
                label: Some("viewer"),
                required_limits: wgpu::Limits::downlevel_webgl2_defaults()
                    .using_resolution(adapter.limits()),
                ..Default::default()
            })
            .await
            .map_err(|e| format!("no {name} device: {e}"))?;
        let lost = failure.clone();
        device.set_device_lost_callback(move |reason, message| {
            keep_first(
                &lost,
                format!("the {name} device was lost ({reason:?}: {message})"),
            );
        });
        let invalid = failure.clone();
        device.on_uncaptured_error(Arc::new(move |e: wgpu::Error| {
            keep_first(&invalid, format!("{name} reported an error: {e}"));
        }));

        let caps = surface.get_capabilities(&adapter);
        // A non-sRGB format when there is one: the colours are sRGB already.
        let format = caps
            .formats
            .iter()
            .copied()
            .find(|f| !f.is_srgb())
            .or_else(|| caps.formats.first().copied())
            .ok_or_else(|| format!("the canvas offers no {name} format"))?;
        let mut config = surface
            .get_default_config(&adapter, width, height)
            .ok_or_else(|| format!("the canvas does not support this {name} adapter"))?;
        config.format = format;
        surface.configure(&device, &config);

        // Pipelines that do not validate (a shader the GL translation refuses) are caught
        // here, so the viewer can fall to the next renderer.
        let scope = device.push_error_scope(wgpu::ErrorFilter::Validation);
        let shader = device.create_shader_module(wgpu::ShaderModuleDescriptor {
            label: Some("viewer.wgsl"),
            source: wgpu::ShaderSource::Wgsl(include_str!("../../../shaders/viewer.wgsl").into()),
        });
        // Buffers are written by the queue, never mapped: some implementations refuse
        // buffers mapped at creation.
        let camera = device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("camera"),
            size: UNIFORM_BYTES,
            usage: wgpu::BufferUsages::UNIFORM | wgpu::BufferUsages::COPY_DST,
            mapped_at_creation: false,
        });
        let layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("camera"),
            entries: &[wgpu::BindGroupLayoutEntry {
                binding: 0,
                visibility: wgpu::ShaderStages::VERTEX_FRAGMENT,
                ty: wgpu::BindingType::Buffer {
                    ty: wgpu::BufferBindingType::Uniform,
                    has_dynamic_offset: false,
                    min_binding_size: None,
                },
                count: None,
            }],
        });
        let bind_group = device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("camera"),
            layout: &layout,
            entries: &[wgpu::BindGroupEntry {
                binding: 0,
                resource: camera.as_entire_binding(),
            }],
        });
        let pipeline_layout = device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
            label: Some("viewer"),
            bind_group_layouts: &[Some(&layout)],
            immediate_size: 0,
        });
        let attributes = wgpu::vertex_attr_array![0 => Float32x3, 1 => Float32x3, 2 => Float32x4];
        let pipeline = |topology: wgpu::PrimitiveTopology| {
            device.create_render_pipeline(&wgpu::RenderPipelineDescriptor {
                label: Some("viewer"),
                layout: Some(&pipeline_layout),
                vertex: wgpu::VertexState {
                    module: &shader,
                    entry_point: Some("vs_main"),
                    compilation_options: Default::default(),
                    buffers: &[Some(wgpu::VertexBufferLayout {
                        array_stride: VERTEX_BYTES as u64,
                        step_mode: wgpu::VertexStepMode::Vertex,
                        attributes: &attributes,
                    })],
                },
                fragment: Some(wgpu::FragmentState {
                    module: &shader,
                    entry_point: Some("fs_main"),
                    compilation_options: Default::default(),
                    targets: &[Some(wgpu::ColorTargetState {
                        format: config.format,
                        blend: Some(wgpu::BlendState::ALPHA_BLENDING),
                        write_mask: wgpu::ColorWrites::ALL,
                    })],
                }),
                primitive: wgpu::PrimitiveState {
                    topology,
                    ..Default::default()
                },
                depth_stencil: Some(wgpu::DepthStencilState {
                    format: DEPTH_FORMAT,
                    depth_write_enabled: Some(true),
                    depth_compare: Some(wgpu::CompareFunction::LessEqual),
                    stencil: Default::default(),
                    bias: Default::default(),
                }),
                multisample: wgpu::MultisampleState::default(),
                multiview_mask: None,
                cache: None,
            })
        };
        let triangles = pipeline(wgpu::PrimitiveTopology::TriangleList);
        let lines = pipeline(wgpu::PrimitiveTopology::LineList);
        if let Some(e) = scope.pop().await {
            return Err(format!("{name} refused the viewer's pipelines: {e}"));
        }
        let depth = depth_view(&device, width, height);
        Ok(GpuRenderer {
            _instance: instance,
            _adapter: adapter,
            surface,
            device,
            queue,
            srgb: if config.format.is_srgb() { 1.0 } else { 0.0 },
            config,
            triangles,
            lines,
            camera,
            bind_group,
            depth,
            vertices: [None, None, None],
            failure,
        })
    }

    /// Uploads `vertices` into reusable buffer `slot`, growing it to the next power of two.
    fn upload(&mut self, slot: usize, vertices: &[Vertex]) -> Option<wgpu::Buffer> {
        if vertices.is_empty() {
            return None;
        }
        let bytes = vertex_bytes(vertices);
        let needed = bytes.len() as u64;
        let fits = self.vertices[slot]
            .as_ref()
            .is_some_and(|(_, size)| *size >= needed);
        if !fits {
            let size = needed.next_power_of_two().max(4096);
            let buffer = self.device.create_buffer(&wgpu::BufferDescriptor {
                label: Some("vertices"),
                size,
                usage: wgpu::BufferUsages::VERTEX | wgpu::BufferUsages::COPY_DST,
                mapped_at_creation: false,
            });
            self.vertices[slot] = Some((buffer, size));
        }
        let (buffer, _) = self.vertices[slot].as_ref()?;
        self.queue.write_buffer(buffer, 0, &bytes);
        Some(buffer.clone())
    }

    /// Follows a new canvas size in device pixels.
    pub fn resize(&mut self, width: u32, height: u32) {
        let (width, height) = (width.max(1), height.max(1));
        if (width, height) != (self.config.width, self.config.height) {
            self.config.width = width;
            self.config.height = height;
            self.surface.configure(&self.device, &self.config);
            self.depth = depth_view(&self.device, width, height);
        }
    }

    /// Draws one frame: Ok(false) when the canvas had no texture to draw into this time,
    /// an error once the device has failed (the renderer is then of no further use).
    pub fn draw(&mut self, frame: &Frame) -> Result<bool, String> {
        if let Some(e) = self.failure.lock().ok().and_then(|f| f.clone()) {
            return Err(e);
        }
        let texture = match self.surface.get_current_texture() {
            wgpu::CurrentSurfaceTexture::Success(t)
            | wgpu::CurrentSurfaceTexture::Suboptimal(t) => t,
            wgpu::CurrentSurfaceTexture::Outdated | wgpu::CurrentSurfaceTexture::Lost => {
                self.surface.configure(&self.device, &self.config);
                return Ok(false);
            }
            _ => return Ok(false),
        };
        let mut uniform = Vec::with_capacity(UNIFORM_BYTES as usize);
        let params = [self.srgb, AMBIENT, SKY, DIFFUSE];
        let light = [LIGHT[0], LIGHT[1], LIGHT[2], 0.0];
        for x in frame
            .view_projection
            .iter()
            .flatten()
            .chain(&light)
            .chain(&params)
        {
            uniform.extend_from_slice(&x.to_le_bytes());
        }
        self.queue.write_buffer(&self.camera, 0, &uniform);
        let shadows = shadow_triangles(frame.shadows);
        let uploaded = [
            self.upload(0, frame.lines),
            self.upload(1, &shadows),
            self.upload(2, frame.body),
        ];
        let buffers = [
            (&uploaded[0], frame.lines.len(), &self.lines),
            (&uploaded[1], shadows.len(), &self.triangles),
            (&uploaded[2], frame.body.len(), &self.triangles),
        ];
        let view = texture
            .texture
            .create_view(&wgpu::TextureViewDescriptor::default());
        let mut encoder = self
            .device
            .create_command_encoder(&wgpu::CommandEncoderDescriptor::default());
        let background = wgpu::Color {
            r: BACKGROUND[0] as f64,
            g: BACKGROUND[1] as f64,
            b: BACKGROUND[2] as f64,
            a: 1.0,
        };
        {
            let mut pass = encoder.begin_render_pass(&wgpu::RenderPassDescriptor {
                label: Some("viewer"),
                color_attachments: &[Some(wgpu::RenderPassColorAttachment {
                    view: &view,
                    depth_slice: None,
                    resolve_target: None,
                    ops: wgpu::Operations {
                        load: wgpu::LoadOp::Clear(background),
                        store: wgpu::StoreOp::Store,
                    },
                })],
                depth_stencil_attachment: Some(wgpu::RenderPassDepthStencilAttachment {
                    view: &self.depth,
                    depth_ops: Some(wgpu::Operations {
                        load: wgpu::LoadOp::Clear(1.0),
                        store: wgpu::StoreOp::Store,
                    }),
                    stencil_ops: None,
                }),
                timestamp_writes: None,
                occlusion_query_set: None,
                multiview_mask: None,
            });
            pass.set_bind_group(0, &self.bind_group, &[]);
            // Lines, then shadows over the grid, then the figure.
            for (buffer, count, pipeline) in buffers {
                if let Some(b) = buffer {
                    pass.set_pipeline(pipeline);
                    pass.set_vertex_buffer(0, b.slice(..));
                    pass.draw(0..count as u32, 0..1);
                }
            }
        }
        self.queue.submit([encoder.finish()]);
        self.queue.present(texture);
        Ok(true)
    }
}
