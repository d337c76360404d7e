use lobes::{job::*, reference::*, stats::histogram::SphereGrid, gpu::*};
fn main() {
    let mut e = GpuEngine::open().unwrap();
    println!("{}", e.gpu.adapter_name());
    for (kind, method) in [(LobeKind::Ward, Method::Ndf),(LobeKind::Ggx, Method::Ndf),(LobeKind::Ggx, Method::Vndf),(LobeKind::Ggx, Method::Bounded),(LobeKind::Beckmann, Method::Ndf),(LobeKind::Beckmann, Method::Vndf)] {
        let lobe = Lobe { kind, method, alpha_x: 0.3, alpha_y: 0.3 };
        let job = Job::Lobe { lobe, incident: reflect::spherical(0.7, 0.0), grid: SphereGrid{rows:64, cols:128} };
        let n = 1u64<<24;
        let r = e.histogram(&job, 1, 0, n, &mut |_| {}).unwrap();
        let c = lobes::cpu::histogram(&job, 1, 0, 1<<16);
        let g = e.histogram(&job, 1, 0, 1<<16, &mut |_| {}).unwrap();
        let diff: u64 = c.bins.iter().zip(&g.counts.bins).map(|(a,b)| a.abs_diff(*b)).sum();
        println!("{kind:?} {method:?} total {} invalid {:?} gpu {:?} wall {:.3} Msps {:.1}  cpu-vs-gpu bin diffs at 65536: {diff}", r.counts.total(), r.counts.invalid, r.gpu_seconds, r.wall_seconds, n as f64 / r.gpu_seconds.unwrap_or(r.wall_seconds) / 1e6);
    }
}
