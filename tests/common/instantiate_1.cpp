// The test-support library: part 1 of the instantiations declared in instantiations.hpp
// (four grid types per file, so that the parts compile side by side).
#include "instantiations.hpp"

INTERVOX_TEST_INSTANTIATIONS(, test::BayesSparse)
INTERVOX_TEST_INSTANTIATIONS(, test::BayesDense)
INTERVOX_TEST_INSTANTIATIONS(, test::BayesBoundedSparse)
INTERVOX_TEST_INSTANTIATIONS(, test::LowerSparse)
