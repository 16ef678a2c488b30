#include "constraints/row_key.h"

#include "plugin/common.h"

namespace taut {

namespace internal {

void CheckRowKeyField(const char* source, const char* field, int bits, std::int64_t value) {
  const std::int64_t end = std::int64_t{1} << bits;
  TAUT_DEMAND(value >= 0 && value < end, source, " row key: ", field, " ", value,
              " out of range [0, ", end, ") (a ", bits, "-bit field)");
}

}  // namespace internal

}  // namespace taut
