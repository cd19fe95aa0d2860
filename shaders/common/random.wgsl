// Random numbers and low-discrepancy points shared by the GI kernels.
// Twins in src/reference/vpl.rs (pcg_hash, radical_inverse_2, hammersley).

// PCG hash (Jarzynski & Olano 2020).
fn pcg_hash(v: u32) -> u32 {
    let state = v * 747796405u + 2891336453u;
    let word = ((state >> ((state >> 28u) + 4u)) ^ state) * 277803737u;
    return (word >> 22u) ^ word;
}

// Uniform float in [0, 1) from the top 24 bits.
fn u01(h: u32) -> f32 {
    return f32(h >> 8u) * (1.0 / 16777216.0);
}

// A small stateful generator seeded from several integers.
struct Rng {
    state: u32,
};

fn rng_new(a: u32, b: u32, c: u32) -> Rng {
    return Rng(pcg_hash(a ^ pcg_hash(b ^ pcg_hash(c))));
}

fn rng_next(r: ptr<function, Rng>) -> f32 {
    (*r).state = pcg_hash((*r).state);
    return u01((*r).state);
}

// Van der Corput radical inverse in base 2.
fn radical_inverse_2(i: u32) -> f32 {
    return f32(reverseBits(i) >> 8u) * (1.0 / 16777216.0);
}

// Point i of an n-point Hammersley set, rotated (Cranley-Patterson) by `rot`.
fn hammersley(i: u32, n: u32, rot: vec2<f32>) -> vec2<f32> {
    let p = vec2<f32>(f32(i) / f32(n), radical_inverse_2(i)) + rot;
    return min(p - floor(p), vec2<f32>(0.99999994));
}
