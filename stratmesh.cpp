// Compiles the stratmesh implementation once, for users who link instead of including.
#define STRATMESH_IMPLEMENTATION
#include "stratmesh.h"
