/* ob_model_internal.h — geometry-private pieces of model loading. Not API:
 * only geometry/ob_model*.c include it. */
#ifndef OB_MODEL_INTERNAL_H
#define OB_MODEL_INTERNAL_H

#include "ob_core.h"

/* Checks a file that assimp would read as a PLY (a .ply extension, or
 * content starting with "ply") before assimp reads it: the first line must
 * be "ply", the header must be well formed and end with end_header,
 * and the data must hold every element the header declares (binary: every
 * record walked, list lengths included; ASCII: at least two bytes per
 * value). assimp 5.2's PLY reader loops forever on a truncated header and
 * reads past its buffer when the header or the data lie; see
 * fuzz/corpus/model-assimp-known. Other files: OB_OK without reading them.
 * Failure: OB_ERR_BAD_MODEL naming the path and the line or element,
 * OB_ERR_IO or OB_ERR_OUT_OF_HOST_MEMORY; logged. [any thread] */
ob_result ob_model_ply_precheck(const char *path);

#endif /* OB_MODEL_INTERNAL_H */
