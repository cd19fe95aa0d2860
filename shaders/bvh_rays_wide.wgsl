// Traces a buffer of rays through the compressed 8-wide BVH (`bench rays` compares it with the binary one).
#include "common/bvh_wide.wgsl"
#include "bvh_rays_entries.wgsl"
