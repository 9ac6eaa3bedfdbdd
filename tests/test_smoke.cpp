#include <doctest/doctest.h>

#include "testkit.hpp"

TEST_CASE("a program prints") {
    CHECK(testkit::printed("print 1+2\n") == "3\n");
}
