// A file that includes a forwarding header on purpose: the check must reject this folder
// (ctest layering.forwarding_detects_include).
#include <intervox/io/slice.hpp>

int main() { return 0; }
