// Old path, kept for existing includes: StrainLimitConstraint is now StrainLimitSource.
#include "constraints/strain_limit_source.h"
