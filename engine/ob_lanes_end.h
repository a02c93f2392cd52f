/* ob_lanes_end.h — undefines what ob_lanes_begin.h and its includer
 * defined, at the end of a lane template. No include guard. */
#undef OB_LANES
#undef OB_VD
#undef OB_VU
#undef OB_LANE
#undef OB_LANE_TARGET
#undef OB_LANE_SQRT
#undef OB_LANES_OF
#undef OB_LANE_PTRS
#undef OB_LANES_PICK
