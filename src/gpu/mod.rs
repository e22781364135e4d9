//! The boundary formulation of the visible integral on a GPU (wgpu compute, behind the `gpu`
//! feature; docs/gpu.md): the kernel of the compute path, one configuration of a light and its
//! occluders (spherical polygons in the shading frame, clipped to the horizon already or by the
//! kernel from V's boundary) per invocation, the same rule as
//! [`geometry::boundary_pieces`](crate::geometry::boundary_pieces) in bounded loops.
//!
//! Besides the form factor, a configuration may carry an LTC lobe's `M⁻¹`: its pieces are mapped
//! and clipped to the lobe's horizon, the crossings closed by horizon arcs in azimuth order
//! ([`geometry::clamped_integral_of_boundary`](crate::geometry::clamped_integral_of_boundary)).
//!
//! Work per configuration is bounded by fixed-size arrays in the shader
//! ([`MAX_EDGES`] edges, [`MAX_CUTS`] cuts per edge, 64 horizon crossings). A configuration
//! beyond them, with a polygon of several loops, or whose horizon crossings do not alternate
//! in the shader's precision, is finished on the CPU by the same formulation and counted in
//! [`GpuIntegrals::fallbacks`]; none is dropped.
//!
//! Precision: f64 where the adapter has `SHADER_F64` and it is asked for, with the
//! trigonometric functions written in the shader (WGSL's built-ins are 32-bit); f32 otherwise.

use crate::geometry::{
    BoundaryScratch, SphericalPolygon, boundary_pieces, clamped_integral_of_boundary,
};
use crate::ltc::edge_integral;
use crate::{Error, Result};
use glam::{DMat3, DVec3};
use std::f64::consts::TAU;

/// Edges per configuration the shader holds (all polygons together).
pub const MAX_EDGES: usize = 64;
/// Cuts per edge the shader holds.
pub const MAX_CUTS: usize = 64;

/// The shader's arithmetic.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Precision {
    F32,
    F64,
}

/// A GPU device and the boundary kernel compiled for it.
pub struct BoundaryKernel {
    device: wgpu::Device,
    queue: wgpu::Queue,
    pipeline: wgpu::ComputePipeline,
    precision: Precision,
    adapter: String,
}

/// What [`BoundaryKernel::integrals`] gives for every configuration, in order.
#[derive(Clone, Debug, Default)]
pub struct GpuIntegrals {
    /// The visible form factor `E(V)` (000 Eq. 9 over V's boundary, over 2π).
    pub diffuse: Vec<f64>,
    /// The lobe's clamped integral `E(clip(M⁻¹V))` where the configuration has a lobe: the
    /// LTC part before `LtcEntry::mix`.
    pub lobe: Vec<Option<f64>>,
    /// Configurations finished on the CPU: beyond the shader's arrays, of several loops, or
    /// whose lobe's horizon crossings did not alternate in the shader's precision.
    pub fallbacks: usize,
}

/// A light and its occluders, as the boundary formulation takes them, and the inverse LTC
/// matrix `M⁻¹` of the lobe to integrate besides the form factor.
pub struct Configuration<'a> {
    pub light: &'a SphericalPolygon,
    pub occluders: &'a [SphericalPolygon],
    pub lobe: Option<DMat3>,
    /// The polygons are not clipped to the horizon (each lies within a hemisphere): the
    /// kernel takes `V ∩ {z ≥ 0}` from V's boundary, cut at the horizon and closed by horizon
    /// arcs, as it takes the lobe's.
    pub clip_here: bool,
}

const WORKGROUP: u32 = 64;

impl BoundaryKernel {
    /// The first adapter of a native backend (Vulkan, Metal, DX12: lavapipe on a machine
    /// without a GPU), with `precision` where it has it: `F64` falls back to `F32` on an adapter
    /// without `SHADER_F64`. An error when there is no adapter.
    pub fn new(precision: Precision) -> Result<BoundaryKernel> {
        pollster::block_on(Self::new_async(precision))
    }

    async fn new_async(precision: Precision) -> Result<BoundaryKernel> {
        let instance = wgpu::Instance::new(wgpu::InstanceDescriptor {
            backends: wgpu::Backends::VULKAN | wgpu::Backends::METAL | wgpu::Backends::DX12,
            ..wgpu::InstanceDescriptor::new_without_display_handle()
        });
        let adapter = instance
            .request_adapter(&wgpu::RequestAdapterOptions::default())
            .await
            .map_err(|e| Error::Request(format!("no GPU adapter (Vulkan, Metal or DX12): {e}")))?;
        let has_f64 = adapter.features().contains(wgpu::Features::SHADER_F64);
        let precision = if precision == Precision::F64 && has_f64 {
            Precision::F64
        } else {
            Precision::F32
        };
        let required_features = if precision == Precision::F64 {
            wgpu::Features::SHADER_F64
        } else {
            wgpu::Features::empty()
        };
        let (device, queue) = adapter
            .request_device(&wgpu::DeviceDescriptor {
                label: Some("penumbra boundary"),
                required_features,
                required_limits: adapter.limits(),
                ..Default::default()
            })
            .await
            .map_err(|e| Error::Request(format!("GPU device: {e}")))?;
        let module = device.create_shader_module(wgpu::ShaderModuleDescriptor {
            label: Some("boundary.wgsl"),
            source: wgpu::ShaderSource::Wgsl(shader_source(precision).into()),
        });
        let pipeline = device.create_compute_pipeline(&wgpu::ComputePipelineDescriptor {
            label: Some("boundary"),
            layout: None,
            module: &module,
            entry_point: Some("main"),
            compilation_options: Default::default(),
            cache: None,
        });
        let info = adapter.get_info();
        Ok(BoundaryKernel {
            device,
            queue,
            pipeline,
            precision,
            adapter: format!("{} ({:?}, {})", info.name, info.backend, info.driver),
        })
    }

    /// The precision the kernel runs in.
    pub fn precision(&self) -> Precision {
        self.precision
    }

    /// The adapter's name, backend and driver.
    pub fn adapter(&self) -> &str {
        &self.adapter
    }

    /// The visible form factor of every configuration, and its lobe's clamped integral where
    /// it has one.
    pub fn integrals(&self, configs: &[Configuration]) -> Result<GpuIntegrals> {
        // Which configurations the shader takes, and their buffers.
        let mut on_gpu = Vec::new();
        let mut buffers = Buffers::default();
        for (i, c) in configs.iter().enumerate() {
            let all = std::iter::once(c.light).chain(c.occluders.iter());
            let edges: usize = all.clone().map(|p| p.vertex_count()).sum();
            if edges > MAX_EDGES || all.clone().any(|p| p.loop_count() > 1) {
                continue;
            }
            buffers.configs.push([
                buffers.polys.len() as u32,
                1 + c.occluders.len() as u32,
                c.lobe.is_some() as u32,
                c.clip_here as u32,
            ]);
            let m = c.lobe.unwrap_or(DMat3::IDENTITY);
            for col in [m.x_axis, m.y_axis, m.z_axis] {
                buffers.lobes.push([col.x, col.y, col.z, 0.0]);
            }
            for p in all {
                buffers
                    .polys
                    .push([buffers.vertices.len() as u32, p.vertex_count() as u32]);
                buffers
                    .vertices
                    .extend(p.vertices().iter().map(|v| [v.x, v.y, v.z, 0.0]));
            }
            on_gpu.push(i);
        }
        let mut out = GpuIntegrals {
            diffuse: vec![f64::NAN; configs.len()],
            lobe: vec![None; configs.len()],
            fallbacks: 0,
        };
        if !on_gpu.is_empty() {
            let results = self.run(&buffers)?;
            for (k, &i) in on_gpu.iter().enumerate() {
                let [diffuse, lobe, status, _] = results[k];
                if status == 0.0 {
                    out.diffuse[i] = diffuse;
                    out.lobe[i] = configs[i].lobe.map(|_| lobe);
                }
            }
        }
        let mut scratch = BoundaryScratch::new();
        let (mut arcs, mut crossings) = (Vec::new(), Vec::new());
        for (i, c) in configs.iter().enumerate() {
            if !out.diffuse[i].is_nan() {
                continue;
            }
            out.fallbacks += 1;
            arcs.clear();
            boundary_pieces(c.light, c.occluders, &mut scratch, |p| {
                arcs.push((p.start, p.end))
            });
            out.diffuse[i] = if c.clip_here {
                clamped_integral_of_boundary(arcs.iter().copied(), &mut crossings, edge_integral)
                    .map_or(f64::NAN, |e| e / TAU)
            } else {
                arcs.iter().map(|&(a, b)| edge_integral(a, b)).sum::<f64>() / TAU
            };
            out.lobe[i] = c.lobe.and_then(|m| {
                let map = |v: DVec3| (m * v).normalize();
                let mapped = arcs.iter().map(|&(a, b)| (map(a), map(b)));
                clamped_integral_of_boundary(mapped, &mut crossings, edge_integral).map(|e| e / TAU)
            });
        }
        Ok(out)
    }

    /// One dispatch: (form factor, lobe, status, 0) per configuration.
    fn run(&self, buffers: &Buffers) -> Result<Vec<[f64; 4]>> {
        let Buffers {
            vertices,
            polys,
            configs,
            lobes,
        } = buffers;
        use wgpu::util::DeviceExt;
        let bytes_of_reals = |values: &mut dyn Iterator<Item = f64>| -> Vec<u8> {
            match self.precision {
                Precision::F32 => values.flat_map(|v| (v as f32).to_le_bytes()).collect(),
                Precision::F64 => values.flat_map(|v| v.to_le_bytes()).collect(),
            }
        };
        let u32_bytes = |words: &mut dyn Iterator<Item = u32>| -> Vec<u8> {
            words.flat_map(|x| x.to_le_bytes()).collect()
        };
        let real_size = match self.precision {
            Precision::F32 => 4,
            Precision::F64 => 8,
        };
        let storage = |label: &str, contents: &[u8]| {
            self.device
                .create_buffer_init(&wgpu::util::BufferInitDescriptor {
                    label: Some(label),
                    contents,
                    usage: wgpu::BufferUsages::STORAGE,
                })
        };
        let vertex_buffer = storage(
            "vertices",
            &bytes_of_reals(&mut vertices.iter().flat_map(|v| v.iter().copied())),
        );
        let poly_buffer = storage("polys", &u32_bytes(&mut polys.iter().flatten().copied()));
        let config_buffer = storage(
            "configs",
            &u32_bytes(&mut configs.iter().flatten().copied()),
        );
        let lobe_buffer = storage(
            "lobes",
            &bytes_of_reals(&mut lobes.iter().flat_map(|v| v.iter().copied())),
        );
        let result_size = (configs.len() * 4 * real_size) as u64;
        let results = self.device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("results"),
            size: result_size,
            usage: wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_SRC,
            mapped_at_creation: false,
        });
        let readback = self.device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("readback"),
            size: result_size,
            usage: wgpu::BufferUsages::MAP_READ | wgpu::BufferUsages::COPY_DST,
            mapped_at_creation: false,
        });
        let layout = self.pipeline.get_bind_group_layout(0);
        let bind = self.device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("boundary"),
            layout: &layout,
            entries: &[
                wgpu::BindGroupEntry {
                    binding: 0,
                    resource: vertex_buffer.as_entire_binding(),
                },
                wgpu::BindGroupEntry {
                    binding: 1,
                    resource: poly_buffer.as_entire_binding(),
                },
                wgpu::BindGroupEntry {
                    binding: 2,
                    resource: config_buffer.as_entire_binding(),
                },
                wgpu::BindGroupEntry {
                    binding: 3,
                    resource: results.as_entire_binding(),
                },
                wgpu::BindGroupEntry {
                    binding: 4,
                    resource: lobe_buffer.as_entire_binding(),
                },
            ],
        });
        let mut encoder = self
            .device
            .create_command_encoder(&wgpu::CommandEncoderDescriptor { label: None });
        {
            let mut pass = encoder.begin_compute_pass(&wgpu::ComputePassDescriptor::default());
            pass.set_pipeline(&self.pipeline);
            pass.set_bind_group(0, &bind, &[]);
            pass.dispatch_workgroups((configs.len() as u32).div_ceil(WORKGROUP), 1, 1);
        }
        encoder.copy_buffer_to_buffer(&results, 0, &readback, 0, result_size);
        self.queue.submit([encoder.finish()]);
        let slice = readback.slice(..);
        let (tx, rx) = std::sync::mpsc::channel();
        slice.map_async(wgpu::MapMode::Read, move |r| {
            let _ = tx.send(r);
        });
        self.device
            .poll(wgpu::PollType::wait_indefinitely())
            .map_err(|e| Error::Request(format!("GPU: {e}")))?;
        rx.recv()
            .map_err(|e| Error::Request(format!("GPU readback: {e}")))?
            .map_err(|e| Error::Request(format!("GPU readback: {e}")))?;
        let data = slice
            .get_mapped_range()
            .map_err(|e| Error::Request(format!("GPU readback: {e}")))?;
        let reals: Vec<f64> = match self.precision {
            Precision::F32 => data
                .chunks_exact(4)
                .map(|b| f32::from_le_bytes([b[0], b[1], b[2], b[3]]) as f64)
                .collect(),
            Precision::F64 => data
                .chunks_exact(8)
                .map(|b| f64::from_le_bytes(b.try_into().unwrap_or([0; 8])))
                .collect(),
        };
        drop(data);
        readback.unmap();
        Ok(reals
            .chunks_exact(4)
            .map(|r| [r[0], r[1], r[2], r[3]])
            .collect())
    }
}

/// What one dispatch uploads: vertices (xyz, 0), polygons (first vertex, count),
/// configurations (first polygon, count, has a lobe, clipped here), and three columns of M⁻¹
/// per configuration.
#[derive(Default)]
struct Buffers {
    vertices: Vec<[f64; 4]>,
    polys: Vec<[u32; 2]>,
    configs: Vec<[u32; 4]>,
    lobes: Vec<[f64; 4]>,
}

/// The shader for `precision`: `real` and its trigonometric functions.
fn shader_source(precision: Precision) -> String {
    let source = include_str!("boundary.wgsl");
    let (real, eps, resolution, trig) = match precision {
        Precision::F32 => (
            "f32",
            // Cross products of unit vectors round at a few 1e-8 in f32.
            "1e-6",
            "9.5e-7",
            "fn atan2r(y: real, x: real) -> real { return atan2(y, x); }\n\
             fn sinr(t: real) -> real { return sin(t); }\n\
             fn cosr(t: real) -> real { return cos(t); }\n",
        ),
        // 8 ulps, as the CPU's `CUT_RESOLUTION`.
        Precision::F64 => (
            "f64",
            "1e-12",
            "1.7763568394002505e-15",
            include_str!("trig_f64.wgsl"),
        ),
    };
    source
        .replace("ENABLE_DIRECTIVES", "")
        .replace("REAL", real)
        .replace("EPS_LINE_VALUE", eps)
        .replace("CUT_RESOLUTION_VALUE", resolution)
        .replace("ATAN2_DEFINITION", trig)
}
