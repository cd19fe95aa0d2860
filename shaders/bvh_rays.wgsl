// Traces a buffer of rays through the binary BVH (tests and the rays/s benchmark).
#include "common/bvh_binary.wgsl"
#include "bvh_rays_entries.wgsl"
