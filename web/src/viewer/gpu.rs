//! The viewer's WebGPU renderer on the page's canvas: one pipeline for triangles (bones and
//! joints, depth-tested), one for lines (grid and root path), one uniform (the camera).
//! It owns its own GPU device: the models run in a worker, and a device cannot cross threads.

use super::scene::{vertex_bytes, Mat4, Vertex, VERTEX_BYTES};

const DEPTH_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::Depth32Float;
const BACKGROUND: wgpu::Color = wgpu::Color {
    r: 0.93,
    g: 0.945,
    b: 0.965,
    a: 1.0,
};

/// What one frame draws.
pub struct Frame<'a> {
    pub view_projection: Mat4,
    pub triangles: &'a [Vertex],
    pub lines: &'a [Vertex],
}

pub struct Renderer {
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
    /// Vertex buffers reused across frames (triangles, lines), grown when a frame needs more.
    vertices: [Option<(wgpu::Buffer, u64)>; 2],
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

impl Renderer {
    /// A renderer on `canvas` (sized in device pixels by the caller).
    pub async fn new(canvas: web_sys::HtmlCanvasElement) -> Result<Renderer, String> {
        let (width, height) = (canvas.width().max(1), canvas.height().max(1));
        let instance = wgpu::Instance::new(wgpu::InstanceDescriptor {
            backends: wgpu::Backends::BROWSER_WEBGPU,
            ..wgpu::InstanceDescriptor::new_without_display_handle()
        });
        let surface = instance
            .create_surface(wgpu::SurfaceTarget::Canvas(canvas))
            .map_err(|e| format!("the canvas cannot show WebGPU: {e}"))?;
        let adapter = instance
            .request_adapter(&wgpu::RequestAdapterOptions {
                compatible_surface: Some(&surface),
                ..Default::default()
            })
            .await
            .map_err(|e| format!("no WebGPU adapter: {e}"))?;
        let (device, queue) = adapter
            .request_device(&wgpu::DeviceDescriptor::default())
            .await
            .map_err(|e| format!("no WebGPU device: {e}"))?;
        let config = surface
            .get_default_config(&adapter, width, height)
            .ok_or("the canvas does not support this adapter")?;
        surface.configure(&device, &config);

        let shader = device.create_shader_module(wgpu::ShaderModuleDescriptor {
            label: Some("viewer.wgsl"),
            source: wgpu::ShaderSource::Wgsl(include_str!("../../../shaders/viewer.wgsl").into()),
        });
        // Buffers are written by the queue, never mapped: some implementations refuse
        // buffers mapped at creation.
        let camera = device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("camera"),
            size: 64,
            usage: wgpu::BufferUsages::UNIFORM | wgpu::BufferUsages::COPY_DST,
            mapped_at_creation: false,
        });
        let layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("camera"),
            entries: &[wgpu::BindGroupLayoutEntry {
                binding: 0,
                visibility: wgpu::ShaderStages::VERTEX,
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
        let attributes = wgpu::vertex_attr_array![0 => Float32x3, 1 => Float32x4];
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
        let depth = depth_view(&device, width, height);
        Ok(Renderer {
            _instance: instance,
            _adapter: adapter,
            surface,
            device,
            queue,
            config,
            triangles,
            lines,
            camera,
            bind_group,
            depth,
            vertices: [None, None],
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

    /// Width / height of the canvas.
    pub fn aspect(&self) -> f32 {
        self.config.width as f32 / self.config.height.max(1) as f32
    }

    /// Draws one frame; false when the canvas had no texture to draw into this time.
    pub fn draw(&mut self, frame: &Frame) -> bool {
        let texture = match self.surface.get_current_texture() {
            wgpu::CurrentSurfaceTexture::Success(t)
            | wgpu::CurrentSurfaceTexture::Suboptimal(t) => t,
            wgpu::CurrentSurfaceTexture::Outdated | wgpu::CurrentSurfaceTexture::Lost => {
                self.surface.configure(&self.device, &self.config);
                return false;
            }
            _ => return false,
        };
        let mut matrix = Vec::with_capacity(64);
        for x in frame.view_projection.iter().flatten() {
            matrix.extend_from_slice(&x.to_le_bytes());
        }
        self.queue.write_buffer(&self.camera, 0, &matrix);
        let tri = self.upload(0, frame.triangles);
        let lin = self.upload(1, frame.lines);
        let view = texture
            .texture
            .create_view(&wgpu::TextureViewDescriptor::default());
        let mut encoder = self
            .device
            .create_command_encoder(&wgpu::CommandEncoderDescriptor::default());
        {
            let mut pass = encoder.begin_render_pass(&wgpu::RenderPassDescriptor {
                label: Some("viewer"),
                color_attachments: &[Some(wgpu::RenderPassColorAttachment {
                    view: &view,
                    depth_slice: None,
                    resolve_target: None,
                    ops: wgpu::Operations {
                        load: wgpu::LoadOp::Clear(BACKGROUND),
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
            if let Some(b) = &lin {
                pass.set_pipeline(&self.lines);
                pass.set_vertex_buffer(0, b.slice(..));
                pass.draw(0..frame.lines.len() as u32, 0..1);
            }
            if let Some(b) = &tri {
                pass.set_pipeline(&self.triangles);
                pass.set_vertex_buffer(0, b.slice(..));
                pass.draw(0..frame.triangles.len() as u32, 0..1);
            }
        }
        self.queue.submit([encoder.finish()]);
        self.queue.present(texture);
        true
    }
}
