// hash.h: the 32-bit position hash of vertex fusion (Griffin et al. 2012, §3.4), the same
// integer mix as src/cpu/vertex_fusion.rs::fuse_hash. Build with
// -DSC_HASH_COLLIDE=<mask> to keep only the masked bits (tests force
// collisions this way; fusion must still be exact).
inline uint fuse_hash(float x, float y, float z)
{
    uint h = as_uint(x) * 0x9E3779B1u;
    h ^= as_uint(y);
    h = (h ^ (h >> 15)) * 0x85EBCA6Bu;
    h ^= as_uint(z);
    h = (h ^ (h >> 13)) * 0xC2B2AE35u;
    h ^= h >> 16;
#ifdef SC_HASH_COLLIDE
    h &= (uint)(SC_HASH_COLLIDE);
#endif
    return h;
}
