/* grid.S: the bulk arrays of grid.h (the directives are in the header). Generated: do not edit. */
#include "grid.h"
