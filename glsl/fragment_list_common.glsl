// Shared by the fragment-list shaders. A pixel's list starts at heads[pixel] (kEndOfList when
// empty); a node is kNodeWords uints: depth bits (float 0..1) with kFrontBit set for a front
// face, the octahedral-encoded outward normal, the next node.
#include "depth_peel_common.glsl"

const uint kNodeWords = 3u;
const uint kFrontBit = 0x80000000u;
const uint kEndOfList = 0xFFFFFFFFu;
