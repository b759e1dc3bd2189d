// Everything a user of meshcast includes: building a blob, walking it on
// this thread, its files, and the host Caster (frame-ahead batches on the
// CPU or the GPU). See README.md, "Use as a library".
#pragma once
#include "meshcast/blob.h"
#include "meshcast/build.h"
#include "meshcast/caster.h"
#include "meshcast/errors.h"
#include "meshcast/jobs.h"
#include "meshcast/mesh.h"
#include "meshcast/ray.h"
#include "meshcast/scene.h"
#include "meshcast/winding_number.h"
