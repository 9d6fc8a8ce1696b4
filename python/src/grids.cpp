/// \file
/// The grid classes: one generic binding (bind_grid<G>) for every named configuration.

#include "grids_bind.hpp"

#include <optional>
#include <sstream>
#include <string_view>

namespace intervox::python {

using namespace bind;

void bind_grids(py::module_& m) {
  for_each_grid([&]<class G>() { bind_grid<G>(m); });
}

}  // namespace intervox::python
