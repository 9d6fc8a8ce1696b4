// The C++ side of the Python insertion tests: inserts raw points or a raw depth image with the C++
// API and saves the grid file, which the tests compare with the grid the Python binding builds.
//
//   intervox_python_oracle cloud <bayes|interval> <resolution> <points.f64> <ox> <oy> <oz> <max_range> <threads> <out>
//   intervox_python_oracle depth <bayes|interval> <resolution> <depth.f32> <w> <h> <fx> <fy> <cx> <cy>
//                                <16 pose values, row-major> <max_range> <out>
// `projective` (and `time-projective`) take the same arguments as `depth` and insert by projection
// (ProjectiveInserter, default surface band).
// With `time-depth` instead of `depth`, <out> is a repeat count: the depth image is inserted into that
// many fresh grids and the median seconds per insertion is printed (the C++ side of
// bench/python_bench.py). `time-query <bayes|interval> <grid.ivx> <points.f64>` prints the seconds of
// one loop of grid.probability(point) over the points.
// Raw files hold native little-endian float64 (x, y, z per point) or float32 (row-major pixels).

#include <intervox/intervox.hpp>
#include <intervox/raycast/projective.hpp>
#include <intervox/raycast/vector_walks.hpp>

#include <algorithm>
#include <chrono>

#include <cstdio>
#include <cstdlib>
#include <exception>
#include <fstream>
#include <iterator>
#include <string>
#include <vector>

namespace {

template <class T>
std::vector<T> read_raw(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw intervox::IoError("cannot open " + path);
  const std::string bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  std::vector<T> v(bytes.size() / sizeof(T));
  std::copy(bytes.data(), bytes.data() + v.size() * sizeof(T), reinterpret_cast<char*>(v.data()));
  return v;
}

template <class Grid>
int run(int argc, char** argv) {
  const std::string mode = argv[1];
  Grid grid(mode == "time-query" ? 1.0 : std::stod(argv[3]));
  if (mode == "cloud" && argc == 11) {
    const auto raw = read_raw<double>(argv[4]);
    std::vector<intervox::Point3> points;
    for (std::size_t i = 0; i + 2 < raw.size(); i += 3) points.emplace_back(raw[i], raw[i + 1], raw[i + 2]);
    const intervox::Point3 origin(std::stod(argv[5]), std::stod(argv[6]), std::stod(argv[7]));
    intervox::InsertOptions o;
    o.max_range = std::stod(argv[8]);
    o.threads = static_cast<unsigned>(std::stoul(argv[9]));
    intervox::insert_point_cloud(grid, origin, points, o);
    intervox::save_grid(argv[10], grid);
    return 0;
  }
  if (mode == "time-query" && argc == 5) {
    const Grid g = intervox::load_grid<Grid>(argv[3]);
    const auto raw = read_raw<double>(argv[4]);
    const auto t0 = std::chrono::steady_clock::now();
    double sum = 0;
    for (std::size_t i = 0; i + 2 < raw.size(); i += 3)
      sum += g.probability(intervox::Point3(raw[i], raw[i + 1], raw[i + 2]));
    const double s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    std::printf("%.9f %.6f\n", s, sum);
    return 0;
  }
  const bool projective = mode == "projective" || mode == "time-projective";
  if ((mode == "depth" || mode == "time-depth" || projective) && argc == 29) {
    intervox::DepthImage img;
    img.width = std::stoi(argv[5]);
    img.height = std::stoi(argv[6]);
    img.depth = read_raw<float>(argv[4]);
    const intervox::PinholeIntrinsics k{img.width,          img.height,         std::stod(argv[7]),
                                        std::stod(argv[8]), std::stod(argv[9]), std::stod(argv[10])};
    intervox::Pose pose;
    for (int r = 0; r < 4; ++r)
      for (int c = 0; c < 4; ++c) pose.matrix()(r, c) = std::stod(argv[11 + 4 * r + c]);
    intervox::InsertOptions o;
    o.max_range = std::stod(argv[27]);
    intervox::ProjectiveInserter pj(o);  // kept across repeats: its scratch, as a depth stream would
    if (mode == "time-depth" || mode == "time-projective") {
      std::vector<double> times;
      for (int r = 0; r < std::stoi(argv[28]); ++r) {
        Grid fresh(grid.resolution());
        const auto t0 = std::chrono::steady_clock::now();
        if (projective)
          pj.insert_depth_image(fresh, img, k, pose);
        else
          intervox::insert_depth_image(fresh, img, k, pose, o);
        times.push_back(std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count());
      }
      std::sort(times.begin(), times.end());
      std::printf("%.9f\n", times[times.size() / 2]);
      return 0;
    }
    if (projective)
      pj.insert_depth_image(grid, img, k, pose);
    else
      intervox::insert_depth_image(grid, img, k, pose, o);
    intervox::save_grid(argv[28], grid);
    return 0;
  }
  std::fprintf(stderr, "usage: see tests/python/insert_oracle.cpp\n");
  return 2;
}

}  // namespace

int main(int argc, char** argv) {
  intervox::use_vector_walks();  // the AVX-512 / AVX2 walks where the processor has them
  try {
    if (argc < 4) {
      std::fprintf(stderr, "usage: see tests/python/insert_oracle.cpp\n");
      return 2;
    }
    const std::string policy = argv[2];
    if (policy == "bayes") return run<intervox::BayesGrid>(argc, argv);
    if (policy == "interval") return run<intervox::IntervalGrid>(argc, argv);
    std::fprintf(stderr, "unknown policy %s\n", policy.c_str());
    return 2;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "error: %s\n", e.what());
    return 1;
  }
}
