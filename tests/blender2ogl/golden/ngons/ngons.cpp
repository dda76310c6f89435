// ngons.cpp: defines the scene of ngons.h (its tables are in the header). Generated: do not edit.
#define B2O_NGONS_DEFINE_SCENE
#include "ngons.h"
