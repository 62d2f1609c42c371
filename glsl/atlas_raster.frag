#version 450
// Atlas raster, fragment stage: value, coverage and the stretch-compensated blur's box
// half-widths (two colour attachments; atlas_raster_frag.glsl).
#extension GL_GOOGLE_include_directive : require
#include "atlas_raster_frag.glsl"
