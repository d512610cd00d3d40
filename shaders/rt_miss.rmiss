// rt back end: every ray ends here (no hit is ever reported); nothing to do.
#version 460
#extension GL_EXT_ray_tracing : require

layout(location = 0) rayPayloadInEXT uint unused_payload;

void main() {}
