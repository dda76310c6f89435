// grid.cpp: defines the scene of grid.h (its tables are in the header). Generated: do not edit.
#define B2O_GRID_DEFINE_SCENE
#include "grid.h"
