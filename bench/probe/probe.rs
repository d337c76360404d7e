//! The kernel-ceiling probe (issue 14): how fast can a plain WGSL kernel sample GGX NDF and
//! histogram it on this adapter, with nothing of lobes' own around it? Runs the compute entry
//! point `main` of FILE (`bench/probe/common.wgsl` followed by one variant; binding 0 a storage
//! buffer of WORDS u32, binding 1 a uniform vec4<u32> seed) over GROUPS workgroups and prints the
//! median wall time of RUNS timed dispatches after one warm-up, the samples per second
//! (GROUPS × SAMPLES_PER_GROUP over the median) and the buffer's sum (so the work is not dead).
//!
//! `cargo run --release --example kernel_probe -- FILE GROUPS WORDS SAMPLES_PER_GROUP [RUNS]`;
//! `bench/mitsuba_compare.py --probe` runs the variants next to Mitsuba in one run.
use std::time::Instant;
use wgpu::util::DeviceExt;

fn main() {
    let a: Vec<String> = std::env::args().collect();
    if a.len() < 5 {
        eprintln!("usage: kernel_probe FILE.wgsl GROUPS WORDS SAMPLES_PER_GROUP [RUNS]");
        std::process::exit(2);
    }
    let src = std::fs::read_to_string(&a[1]).unwrap_or_else(|e| panic!("{}: {e}", a[1]));
    let groups: u32 = a[2].parse().expect("GROUPS: a whole number");
    let words: u64 = a[3].parse().expect("WORDS: a whole number");
    let per_group: f64 = a[4].parse().expect("SAMPLES_PER_GROUP: a number");
    let runs: usize = a.get(5).map(|s| s.parse().expect("RUNS: a whole number")).unwrap_or(5);
    let inst = wgpu::Instance::new(wgpu::InstanceDescriptor::new_without_display_handle_from_env());
    let adapter = pollster::block_on(inst.request_adapter(&Default::default())).expect("no GPU adapter (docs/install.md)");
    let desc = wgpu::DeviceDescriptor { required_limits: adapter.limits(), ..Default::default() };
    let (device, queue) = pollster::block_on(adapter.request_device(&desc)).expect("device");
    let module = device.create_shader_module(wgpu::ShaderModuleDescriptor { label: None, source: wgpu::ShaderSource::Wgsl(src.into()) });
    let pipe = device.create_compute_pipeline(&wgpu::ComputePipelineDescriptor {
        label: None,
        layout: None,
        module: &module,
        entry_point: Some("main"),
        compilation_options: Default::default(),
        cache: None,
    });
    let usage = wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_SRC | wgpu::BufferUsages::COPY_DST;
    let buf = device.create_buffer(&wgpu::BufferDescriptor { label: None, size: words * 4, usage, mapped_at_creation: false });
    let read_usage = wgpu::BufferUsages::MAP_READ | wgpu::BufferUsages::COPY_DST;
    let read = device.create_buffer(&wgpu::BufferDescriptor { label: None, size: words * 4, usage: read_usage, mapped_at_creation: false });
    let seed = [7u32, 0, 0, 0];
    let uni = device.create_buffer_init(&wgpu::util::BufferInitDescriptor { label: None, contents: bytemuck::cast_slice(&seed), usage: wgpu::BufferUsages::UNIFORM });
    let bg = device.create_bind_group(&wgpu::BindGroupDescriptor {
        label: None,
        layout: &pipe.get_bind_group_layout(0),
        entries: &[wgpu::BindGroupEntry { binding: 0, resource: buf.as_entire_binding() }, wgpu::BindGroupEntry { binding: 1, resource: uni.as_entire_binding() }],
    });
    let mut times = vec![];
    for r in 0..=runs {
        let mut enc = device.create_command_encoder(&Default::default());
        enc.clear_buffer(&buf, 0, None);
        {
            let mut p = enc.begin_compute_pass(&Default::default());
            p.set_pipeline(&pipe);
            p.set_bind_group(0, &bg, &[]);
            let (gx, gy) = if groups > 65535 { (65535, groups.div_ceil(65535)) } else { (groups, 1) };
            p.dispatch_workgroups(gx, gy, 1);
        }
        enc.copy_buffer_to_buffer(&buf, 0, &read, 0, words * 4);
        let t = Instant::now();
        queue.submit([enc.finish()]);
        device.poll(wgpu::PollType::wait_indefinitely()).expect("poll");
        if r > 0 {
            times.push(t.elapsed().as_secs_f64());
        }
    }
    read.slice(..).map_async(wgpu::MapMode::Read, |_| {});
    device.poll(wgpu::PollType::wait_indefinitely()).expect("poll");
    let sum: u64 = bytemuck::cast_slice::<u8, u32>(&read.slice(..).get_mapped_range().unwrap()).iter().map(|&x| x as u64).sum();
    times.sort_by(f64::total_cmp);
    let med = times[times.len() / 2];
    let n = groups as f64 * per_group;
    println!("{} median {:.4} s  {:.3e} samples/s  sum {}  adapter {}", a[1], med, n / med, sum, adapter.get_info().driver_info);
}
