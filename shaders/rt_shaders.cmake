# The ray-tracing back end's shaders (server/gpu/rt/). GL_EXT_ray_tracing needs SPIR-V 1.4,
# hence Vulkan 1.2 as the target environment.
octomap_rt_embed_shader(rt_shoot.rgen rt_shoot_rgen_spv TARGET_ENV vulkan1.2)
octomap_rt_embed_shader(rt_voxel.rint rt_voxel_rint_spv TARGET_ENV vulkan1.2)
octomap_rt_embed_shader(rt_miss.rmiss rt_miss_rmiss_spv TARGET_ENV vulkan1.2)
