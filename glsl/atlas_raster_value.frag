#version 450
// Atlas raster, fragment stage without the half-widths: value and coverage only (one colour
// attachment), for a blur with one width in texels (atlas_raster_frag.glsl).
#extension GL_GOOGLE_include_directive : require
#define ATLAS_RASTER_VALUE_ONLY
#include "atlas_raster_frag.glsl"
