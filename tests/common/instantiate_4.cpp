// The test-support library: part 4 of the instantiations declared in instantiations.hpp
// (four grid types per file, so that the parts compile side by side).
#include "instantiations.hpp"

INTERVOX_TEST_INSTANTIATIONS(, test::NamedIntervalGrid)
INTERVOX_TEST_INSTANTIATIONS(, test::NamedDenseIntervalGrid)
INTERVOX_TEST_INSTANTIATIONS(, test::NamedDirichletGrid)
INTERVOX_TEST_INSTANTIATIONS(, test::NamedBeliefGrid)
