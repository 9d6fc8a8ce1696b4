// The test-support library: part 2 of the instantiations declared in instantiations.hpp
// (four grid types per file, so that the parts compile side by side).
#include "instantiations.hpp"

INTERVOX_TEST_INSTANTIATIONS(, test::MeanDense)
INTERVOX_TEST_INSTANTIATIONS(, test::MeanBoundedSparse)
INTERVOX_TEST_INSTANTIATIONS(, test::UpperSparse)
INTERVOX_TEST_INSTANTIATIONS(, test::UpperDense)
