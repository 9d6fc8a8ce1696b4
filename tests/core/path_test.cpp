// detail::check_path: a path with a NUL byte would name another file ("a\0b.ivx" is "a" to the
// operating system); it is refused with InvalidArgument naming the path, the NUL shown as \0.
#include <catch2/catch.hpp>
#include <intervox/core/path.hpp>

#include <string>

namespace iv = intervox;

TEST_CASE("a path with a NUL byte is refused, naming the path with the NUL shown", "[core][path]") {
  using namespace std::string_literals;
  CHECK_NOTHROW(iv::detail::check_path("a/b.ivx"));
  CHECK_NOTHROW(iv::detail::check_path(""));
  try {
    iv::detail::check_path("dir/a\0b.ivx"s);
    FAIL("not refused");
  } catch (const iv::InvalidArgument& e) {
    const std::string msg = e.what();
    CHECK(msg.find("dir/a\\0b.ivx") != std::string::npos);
    CHECK(msg.find("NUL") != std::string::npos);
    CHECK(msg.find('\0') == std::string::npos);
  }
  CHECK_THROWS_AS(iv::detail::check_path("\0"s), iv::InvalidArgument);
  CHECK_THROWS_AS(iv::detail::check_path("x\0"s), iv::InvalidArgument);
}
