// One run per output folder (examples/common/output_lock.hpp), as experiments and
// mobile_exploration take it: a second run into a folder in use is refused naming the holder.
#include <catch2/catch.hpp>

#include "common/output_lock.hpp"

#include <sys/wait.h>
#include <unistd.h>

#include <cstdio>
#include <filesystem>
#include <random>
#include <string>

TEST_CASE("a second run into an output folder in use is refused, naming the run that holds it", "[experiments][lock]") {
  namespace fs = std::filesystem;
  const fs::path dir = fs::temp_directory_path() / ("intervox_lock_" + std::to_string(std::random_device{}()));
  fs::remove_all(dir);
  int to_child[2], to_parent[2];
  REQUIRE(::pipe(to_child) == 0);
  REQUIRE(::pipe(to_parent) == 0);
  const pid_t child = ::fork();
  REQUIRE(child >= 0);
  if (child == 0) {  // another run: takes the lock, says so, waits to be told to end
    char c = 0;
    {
      const examples::OutputFolderLock lock(dir.string());
      (void)!::write(to_parent[1], "l", 1);
      (void)!::read(to_child[0], &c, 1);
    }
    ::_exit(0);
  }
  char c = 0;
  REQUIRE(::read(to_parent[0], &c, 1) == 1);
  CHECK_THROWS_WITH(examples::OutputFolderLock(dir.string()),
                    Catch::Contains("output folder " + dir.string() + " is in use by another run (pid " +
                                    std::to_string(child) + ")"));
  (void)!::write(to_child[1], "x", 1);
  int status = 0;
  REQUIRE(::waitpid(child, &status, 0) == child);
  // The lock ends with the run that held it (here: the child's exit); a later run takes it.
  CHECK_NOTHROW(examples::OutputFolderLock(dir.string()));
  {
    const examples::OutputFolderLock first(dir.string());
    CHECK_THROWS_WITH(examples::OutputFolderLock(dir.string()),
                      Catch::Contains("(pid " + std::to_string(::getpid()) + ")"));
  }
  for (int fd : {to_child[0], to_child[1], to_parent[0], to_parent[1]}) ::close(fd);
  fs::remove_all(dir);
}

TEST_CASE("an output folder's lock file is removed when its run ends and does not block a later run",
          "[experiments][lock]") {
  namespace fs = std::filesystem;
  const fs::path dir = fs::temp_directory_path() / ("intervox_lock_end_" + std::to_string(std::random_device{}()));
  fs::remove_all(dir);
  {
    const examples::OutputFolderLock lock(dir.string());
    CHECK(fs::exists(dir / examples::OutputFolderLock::kFileName));
  }
  CHECK_FALSE(fs::exists(dir / examples::OutputFolderLock::kFileName));
  // A file left by a run that crashed (no lock held on it) does not block.
  {
    std::FILE* f = std::fopen((dir / examples::OutputFolderLock::kFileName).c_str(), "w");
    std::fputs("12345\n", f);
    std::fclose(f);
  }
  CHECK_NOTHROW(examples::OutputFolderLock(dir.string()));
  fs::remove_all(dir);
}
