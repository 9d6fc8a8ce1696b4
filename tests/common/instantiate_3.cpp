// The test-support library: part 3 of the instantiations declared in instantiations.hpp
// (four grid types per file, so that the parts compile side by side).
#include "instantiations.hpp"

INTERVOX_TEST_INSTANTIATIONS(, test::CompactSparse)
INTERVOX_TEST_INSTANTIATIONS(, test::CompactBoundedSparse)
INTERVOX_TEST_INSTANTIATIONS(, test::DirichletDense)
INTERVOX_TEST_INSTANTIATIONS(, test::BeliefSparse)
