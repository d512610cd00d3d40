# The compute shaders: the vulkan back end's shooting passes (server/gpu/vulkan_backend.cpp)
# and the GPU ray space's compaction (server/gpu/gpu_ray_space.cpp). The ray-tracing back
# end lists its own shaders in rt_shaders.cmake.
octomap_rt_embed_shader(shoot_octomap.comp shoot_octomap_spv)
octomap_rt_embed_shader(shoot_exact.comp shoot_exact_spv)
octomap_rt_embed_shader(compact_touched.comp compact_touched_spv)
octomap_rt_embed_shader(prepare_rays.comp prepare_rays_spv)
include(${CMAKE_CURRENT_LIST_DIR}/rt_shaders.cmake OPTIONAL)
# The exact distance transform's passes (server/gpu/distance_transform.cpp).
octomap_rt_embed_shader(edt_rows.comp edt_rows_spv)
octomap_rt_embed_shader(edt_envelope.comp edt_envelope_spv)
