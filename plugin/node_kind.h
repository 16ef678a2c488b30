// Role of a node in the implicit step.
#pragma once

namespace taut {

enum class NodeKind : unsigned char {
  kFree,       // integrated
  kFixed,      // v = 0
  kKinematic,  // v driven to a target position each step
};

}  // namespace taut
