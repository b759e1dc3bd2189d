// Method 2 of seed 000 §7 over bitpack 128-lane records: pass 2.
#version 460
#extension GL_GOOGLE_include_directive : require
#extension GL_EXT_shader_explicit_arithmetic_types_int64 : require
#include "shaders/soa128_bitpack.glsl"
#include "shaders/aabblist_test.glsl"
