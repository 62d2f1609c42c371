// Shared by the fragment-list shaders. A pixel's list starts at heads[pixel] (SDFKIT_END_OF_LIST
// when empty); a node is SDFKIT_NODE_WORDS uints: depth bits (float 0..1) with SDFKIT_FRONT_BIT
// set for a front face, the octahedral-encoded outward normal, the next node (the constants are
// in sdf_definition_shared.h, shared with the C++ host code).
#ifndef SDFKIT_FRAGMENT_LIST_COMMON_GLSL
#define SDFKIT_FRAGMENT_LIST_COMMON_GLSL
#include "depth_peel_common.glsl"

#endif  // SDFKIT_FRAGMENT_LIST_COMMON_GLSL
