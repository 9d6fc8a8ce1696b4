#pragma once
// The main of every example program: whatever goes wrong while it runs (bad input, a file that
// cannot be written, memory) ends as one line "program: error: ..." on stderr and a non-zero exit
// code, never as an abort. Command-line parsing (CLI11) is added by cli.hpp beside this file.
#include <intervox/core/error.hpp>

#include <cstdio>
#include <exception>
#include <filesystem>
#include <new>
#include <string_view>

namespace examples {

/// Exit code of a program whose command line was wrong (unknown option, bad value).
inline constexpr int kUsageError = 2;
/// Exit code of a program that failed while it ran (bad input data, unwritable output, ...).
inline constexpr int kRunError = 1;

/// Prints "program: error: what" to stderr.
inline void report_error(std::string_view program, std::string_view what) {
  std::fprintf(stderr, "%.*s: error: %.*s\n", static_cast<int>(program.size()), program.data(),
               static_cast<int>(what.size()), what.data());
}

/// Runs `body()` (returning the exit code) and turns every exception into an error line on stderr
/// and kRunError: intervox::Error (bad input, unreadable or unwritable files),
/// std::filesystem::filesystem_error (e.g. an output folder below a regular file), std::bad_alloc
/// and any other exception.
template <class Body>
int guarded_main(std::string_view program, Body&& body) noexcept {
  try {
    try {
      return body();
    } catch (const intervox::Error& e) {
      report_error(program, e.what());
    } catch (const std::filesystem::filesystem_error& e) {
      report_error(program, e.what());
    } catch (const std::bad_alloc&) {
      report_error(program, "out of memory");
    } catch (const std::exception& e) {
      report_error(program, e.what());
    } catch (...) {
      report_error(program, "unknown failure");
    }
  } catch (...) {  // reporting itself failed
  }
  return kRunError;
}

/// The main of a program that takes no arguments: `--help` (or `-h`) prints "usage: program" and
/// \p what, any other argument is a usage error (kUsageError); otherwise guarded_main(body).
template <class Body>
int main_without_arguments(int argc, char** argv, std::string_view program, std::string_view what, Body&& body) {
  const std::string_view arg = argc > 1 ? argv[1] : "";
  if (argc == 2 && (arg == "-h" || arg == "--help")) {
    std::printf("usage: %.*s\n%.*s; takes no arguments\n", static_cast<int>(program.size()), program.data(),
                static_cast<int>(what.size()), what.data());
    return 0;
  }
  if (argc > 1) {
    std::fprintf(stderr, "%.*s: error: expected no arguments (usage: %.*s; --help for more)\n",
                 static_cast<int>(program.size()), program.data(), static_cast<int>(program.size()), program.data());
    return kUsageError;
  }
  return guarded_main(program, body);
}

}  // namespace examples
