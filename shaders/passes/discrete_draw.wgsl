#define_import_path lobes::draw
#import lobes::job::discrete_sample
#import lobes::params::lobes_params
#import lobes::rng::rng_uniforms

// The draw of a discrete job, which the counting kernel (shaders/passes/kernel.wgsl) calls: the
// item of sample `index`, drawn by `discrete_sample`, the generated call site in `lobes::job`
// of the job's method (CDF, blocked CDF or alias table: src/engine/gpu/compose.rs).

fn draw(index: vec2<u32>) -> u32 {
    let u = rng_uniforms(lobes_params.seed, index);
    return discrete_sample(u, lobes_params.n_items, lobes_params.last_positive);
}
