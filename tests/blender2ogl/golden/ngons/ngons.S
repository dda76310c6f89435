/* ngons.S: the bulk arrays of ngons.h (the directives are in the header). Generated: do not edit. */
#include "ngons.h"
