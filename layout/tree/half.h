// IEEE 754 binary16 conversion with directed rounding, for QuadTreeHalfFloat
// bounds (seed 000 §5.7): minima round toward -inf and maxima toward +inf, so a
// decoded box always contains the box that was encoded.
#pragma once
#include <cstdint>

namespace meshcast::layout {

float half_to_float(uint16_t h);
uint16_t float_to_half_down(float f);  // largest half <= f
uint16_t float_to_half_up(float f);    // smallest half >= f

}  // namespace meshcast::layout
