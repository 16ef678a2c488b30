// Old path, kept for existing includes: EnergyLimitConstraint is now EnergyLimitSource.
#include "constraints/energy_limit_source.h"
