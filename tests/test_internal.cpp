// White-box tests: this file includes the implementation to reach its internal functions.
#include "../pray.cpp"

#include <doctest/doctest.h>
