// StepStats is a plain aggregate; this unit keeps the constraints library non-empty until the
// solver files join it.
#include "constraints/step_stats.h"
