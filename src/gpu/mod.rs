//! The boundary formulation of the visible integral on a GPU (wgpu compute, behind the `gpu`
//! feature; docs/gpu.md): the kernel of the compute path, one configuration of a light and its
//! occluders (spherical polygons in the shading frame, clipped to the horizon) per invocation,
//! the same rule as [`geometry::boundary_pieces`](crate::geometry::boundary_pieces) in bounded
//! loops.
//!
//! Work per configuration is bounded by fixed-size arrays in the shader
//! ([`MAX_EDGES`] edges, [`MAX_CUTS`] cuts per edge). A configuration beyond them, or with a
//! polygon of several loops, is finished on the CPU by the same formulation and counted in
//! [`GpuFormFactors::fallbacks`]; none is dropped.
//!
//! Precision: f64 where the adapter has `SHADER_F64` and it is asked for, with the
//! trigonometric functions written in the shader (WGSL's built-ins are 32-bit); f32 otherwise.

use crate::geometry::{BoundaryScratch, SphericalPolygon, visible_integral_from_boundary};
use crate::ltc::edge_integral;
use crate::{Error, Result};
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

/// What [`BoundaryKernel::form_factors`] gives: the visible form factor of every
/// configuration, in order.
#[derive(Clone, Debug, Default)]
pub struct GpuFormFactors {
    pub values: Vec<f64>,
    /// Configurations finished on the CPU: beyond the shader's arrays, or of several loops.
    pub fallbacks: usize,
}

/// A light and its occluders, as the boundary formulation takes them.
pub struct Configuration<'a> {
    pub light: &'a SphericalPolygon,
    pub occluders: &'a [SphericalPolygon],
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

    /// The visible form factor `(1/2π) Σ` of the boundary pieces' edge integrals of every
    /// configuration.
    pub fn form_factors(&self, configs: &[Configuration]) -> Result<GpuFormFactors> {
        // Which configurations the shader takes, and their buffers.
        let mut on_gpu = Vec::new();
        let (mut vertices, mut polys, mut descs) = (Vec::<[f64; 4]>::new(), Vec::new(), Vec::new());
        for (i, c) in configs.iter().enumerate() {
            let all = std::iter::once(c.light).chain(c.occluders.iter());
            let edges: usize = all.clone().map(|p| p.vertex_count()).sum();
            if edges > MAX_EDGES || all.clone().any(|p| p.loop_count() > 1) {
                continue;
            }
            descs.push([polys.len() as u32, 1 + c.occluders.len() as u32]);
            for p in all {
                polys.push([vertices.len() as u32, p.vertex_count() as u32]);
                vertices.extend(p.vertices().iter().map(|v| [v.x, v.y, v.z, 0.0]));
            }
            on_gpu.push(i);
        }
        let mut out = GpuFormFactors {
            values: vec![f64::NAN; configs.len()],
            fallbacks: 0,
        };
        if !on_gpu.is_empty() {
            let results = self.run(&vertices, &polys, &descs)?;
            for (k, &i) in on_gpu.iter().enumerate() {
                let (value, status) = results[k];
                if status == 0.0 {
                    out.values[i] = value;
                }
            }
        }
        let mut scratch = BoundaryScratch::new();
        for (i, c) in configs.iter().enumerate() {
            if out.values[i].is_nan() {
                out.fallbacks += 1;
                out.values[i] = visible_integral_from_boundary(
                    c.light,
                    c.occluders,
                    &mut scratch,
                    edge_integral,
                ) / TAU;
            }
        }
        Ok(out)
    }

    /// One dispatch: (value, status) per configuration.
    fn run(
        &self,
        vertices: &[[f64; 4]],
        polys: &[[u32; 2]],
        configs: &[[u32; 2]],
    ) -> Result<Vec<(f64, f64)>> {
        use wgpu::util::DeviceExt;
        let bytes_of_reals = |values: &mut dyn Iterator<Item = f64>| -> Vec<u8> {
            match self.precision {
                Precision::F32 => values.flat_map(|v| (v as f32).to_le_bytes()).collect(),
                Precision::F64 => values.flat_map(|v| v.to_le_bytes()).collect(),
            }
        };
        let u32_bytes = |pairs: &[[u32; 2]]| -> Vec<u8> {
            pairs
                .iter()
                .flat_map(|p| p.iter().flat_map(|x| x.to_le_bytes()))
                .collect()
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
        let poly_buffer = storage("polys", &u32_bytes(polys));
        let config_buffer = storage("configs", &u32_bytes(configs));
        let result_size = (configs.len() * 2 * real_size) as u64;
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
        Ok(reals.chunks_exact(2).map(|r| (r[0], r[1])).collect())
    }
}

/// The shader for `precision`: `real` and its trigonometric functions.
fn shader_source(precision: Precision) -> String {
    let source = include_str!("boundary.wgsl");
    let (real, eps, trig) = match precision {
        Precision::F32 => (
            "f32",
            // Cross products of unit vectors round at a few 1e-8 in f32.
            "1e-6",
            "fn atan2r(y: real, x: real) -> real { return atan2(y, x); }\n\
             fn sinr(t: real) -> real { return sin(t); }\n\
             fn cosr(t: real) -> real { return cos(t); }\n",
        ),
        Precision::F64 => ("f64", "1e-12", include_str!("trig_f64.wgsl")),
    };
    source
        .replace("ENABLE_DIRECTIVES", "")
        .replace("REAL", real)
        .replace("EPS_LINE_VALUE", eps)
        .replace("ATAN2_DEFINITION", trig)
}
