// Included right after a ray pass's #extension lines. Built with
// -DOCTOMAP_RT_SHADER_FLUSH_DENORMALS=ON (for tests only, on a device that supports the mode,
// lavapipe does), the pass flushes fp32 subnormals to 0 as NVIDIA's GPUs do by default, so the
// dev machine shows what an H200 computes (docs/DEVELOPING.md). Off: the device's default.
#ifdef ORT_FLUSH_DENORMALS
#extension GL_EXT_spirv_intrinsics : require
spirv_execution_mode(extensions = ["SPV_KHR_float_controls"], capabilities = [4465], 4460, 32);  // DenormFlushToZero 32
#endif
