#define STRATMESH_IMPLEMENTATION
#include "../consumer.cpp"
