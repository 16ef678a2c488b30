// Placing a deformable body at a Bullet pose (a rotation and a translation of its rest mesh).
#pragma once

#include <LinearMath/btTransform.h>

#include "plugin/deformable_body.h"

namespace taut {

// Moves every node of `body` to pose * its rest position [m] (velocities kept). Co-rotational
// elements are rotation invariant, so the body is at rest there. Throws InputError naming the
// body unless pose is finite and its basis a rotation (orthonormal to 1e-5, det +1): a scaling or
// a mirror would strain the body.
void PlaceAtPose(DeformableBody& body, const btTransform& pose);

}  // namespace taut
