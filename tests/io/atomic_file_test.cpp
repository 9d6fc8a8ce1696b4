// How every writer of the io layer saves a file (detail/atomic_file.hpp): exclusive temporaries,
// concurrent savers in several processes, symbolic links, permissions, long names, syncing and
// failures.
#include <catch2/catch.hpp>

#include <sys/socket.h>
#include <sys/stat.h>
#include <sys/syscall.h>
#include <sys/un.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <climits>
#include <filesystem>
#include <string>
#include <vector>

#include "grid_types.hpp"
#include <intervox/explain/explained_space.hpp>
#include <intervox/io/detail/atomic_file.hpp>
#include <intervox/io/explained_file.hpp>
#include <intervox/io/grid_file.hpp>
#include <intervox/io/octomap.hpp>
#include <intervox/io/ply_writer.hpp>
#include <intervox/update/bayes_log_odds.hpp>
#include <intervox/view/html_view.hpp>
#include "io_test_util.hpp"

using namespace intervox;
namespace fs = std::filesystem;

namespace {

// Every fsync of this test program passes through here: while a FsyncSpy is alive, the path of each
// synced descriptor is recorded, and the call can be made to fail.
struct FsyncLog {
  bool recording = false;
  int fail_with = 0;
  std::vector<std::string> paths;
};

FsyncLog& fsync_log() {
  static FsyncLog log;
  return log;
}

class FsyncSpy {
 public:
  explicit FsyncSpy(int fail_with = 0) { fsync_log() = FsyncLog{true, fail_with, {}}; }
  ~FsyncSpy() { fsync_log() = FsyncLog{}; }
  FsyncSpy(const FsyncSpy&) = delete;
  FsyncSpy& operator=(const FsyncSpy&) = delete;
  const std::vector<std::string>& paths() const { return fsync_log().paths; }
};

void save_text(const std::string& path, const std::string& text) {
  detail::write_file_atomically(path, [&](std::FILE* f) { detail::write_bytes(f, text.data(), text.size(), path); });
}

unsigned permissions_of(const std::string& path) {
  struct stat s {};
  REQUIRE(::stat(path.c_str(), &s) == 0);
  return s.st_mode & 07777;
}

using SparseBayes = VoxelGrid<BayesLogOdds, Entropy, SparseStorage>;

}  // namespace

extern "C" int fsync(int fd) {
  FsyncLog& log = fsync_log();
  if (log.recording) {
    char target[PATH_MAX];
    const std::string link = "/proc/self/fd/" + std::to_string(fd);
    const ssize_t n = ::readlink(link.c_str(), target, sizeof target);
    log.paths.emplace_back(n > 0 ? std::string(target, static_cast<std::size_t>(n)) : std::string("?"));
    if (log.fail_with != 0) {
      errno = log.fail_with;
      return -1;
    }
  }
  return static_cast<int>(::syscall(SYS_fsync, fd));
}

TEST_CASE("processes saving to one path at once always leave a complete file of one of them", "[io][atomic_file]") {
  const TempDir dir;
  const std::string path = dir.file("map.ivx");
  constexpr int kWriters = 4;
  constexpr int kSaves = 30;
  std::vector<SparseBayes> grids;
  std::vector<std::string> expected;
  for (int w = 0; w < kWriters; ++w) {
    grids.emplace_back(0.1);
    fill_randomly(grids.back(), 4000, 100 + static_cast<std::uint32_t>(w));
    expected.push_back(save_grid_to_memory(grids.back()));
  }
  std::vector<pid_t> writers;
  for (int w = 0; w < kWriters; ++w) {
    const pid_t pid = ::fork();
    REQUIRE(pid >= 0);
    if (pid == 0) {  // a writer: exit status 0 when every save reported success
      int failures = 0;
      for (int s = 0; s < kSaves; ++s) {
        try {
          save_grid(path, grids[static_cast<std::size_t>(w)]);
        } catch (...) {
          ++failures;
        }
      }
      ::_exit(failures == 0 ? 0 : 1);
    }
    writers.push_back(pid);
  }
  // Meanwhile every version of the file that a reader sees must be one writer's complete file.
  int versions_seen = 0, foreign_versions = 0, running = kWriters;
  std::vector<int> status(kWriters, -1);
  while (running > 0) {
    if (fs::exists(path)) {
      const std::string now = read_all(path);
      ++versions_seen;
      if (std::find(expected.begin(), expected.end(), now) == expected.end()) ++foreign_versions;
    }
    for (int w = 0; w < kWriters; ++w) {
      int st = 0;
      if (status[static_cast<std::size_t>(w)] == -1 &&
          ::waitpid(writers[static_cast<std::size_t>(w)], &st, WNOHANG) > 0) {
        status[static_cast<std::size_t>(w)] = WIFEXITED(st) ? WEXITSTATUS(st) : 128;
        --running;
      }
    }
  }
  INFO(versions_seen << " versions read while the writers ran");
  CHECK(foreign_versions == 0);
  for (int w = 0; w < kWriters; ++w) CHECK(status[static_cast<std::size_t>(w)] == 0);
  const std::string last = read_all(path);
  CHECK(std::find(expected.begin(), expected.end(), last) != expected.end());
  CHECK(load_grid<SparseBayes>(path).observed_count() > 0);
  CHECK(count_files(dir.path()) == 1);  // no temporary left behind
}

TEST_CASE("saving through a symbolic link writes its target and keeps the link", "[io][atomic_file]") {
  const TempDir dir;
  SECTION("a relative link in the same folder") {
    save_text(dir.file("real.txt"), "old");
    fs::create_symlink("real.txt", dir.file("link.txt"));
    save_text(dir.file("link.txt"), "new");
    CHECK(fs::is_symlink(dir.file("link.txt")));
    CHECK(fs::read_symlink(dir.file("link.txt")) == "real.txt");
    CHECK(read_all(dir.file("real.txt")) == "new");
    CHECK(count_files(dir.path()) == 2);
  }
  SECTION("a link to a file in another folder: the temporary lives beside the target") {
    fs::create_directory(dir.file("a"));
    fs::create_directory(dir.file("b"));
    save_text(dir.file("b/real.txt"), "old");
    fs::create_symlink(dir.file("b/real.txt"), dir.file("a/link.txt"));
    {
      const FsyncSpy spy;
      save_text(dir.file("a/link.txt"), "new");
      REQUIRE(!spy.paths().empty());
      CHECK(fs::path(spy.paths().front()).parent_path() == fs::canonical(dir.file("b")));
    }
    CHECK(fs::is_symlink(dir.file("a/link.txt")));
    CHECK(read_all(dir.file("b/real.txt")) == "new");
    CHECK(count_files(dir.file("a")) == 1);
    CHECK(count_files(dir.file("b")) == 1);
  }
  SECTION("a chain of links") {
    save_text(dir.file("real.txt"), "old");
    fs::create_symlink("real.txt", dir.file("link1.txt"));
    fs::create_symlink("link1.txt", dir.file("link2.txt"));
    save_text(dir.file("link2.txt"), "new");
    CHECK(fs::is_symlink(dir.file("link1.txt")));
    CHECK(fs::is_symlink(dir.file("link2.txt")));
    CHECK(read_all(dir.file("real.txt")) == "new");
    CHECK(count_files(dir.path()) == 3);
  }
  SECTION("a dangling link gets its target created") {
    fs::create_symlink("missing.txt", dir.file("link.txt"));
    save_text(dir.file("link.txt"), "new");
    CHECK(fs::is_symlink(dir.file("link.txt")));
    CHECK(read_all(dir.file("missing.txt")) == "new");
  }
  SECTION("a loop of links is an error naming the path") {
    fs::create_symlink("loop2.txt", dir.file("loop1.txt"));
    fs::create_symlink("loop1.txt", dir.file("loop2.txt"));
    CHECK_THROWS_WITH(save_text(dir.file("loop1.txt"), "new"), Catch::Contains("loop1.txt"));
    CHECK(count_files(dir.path()) == 2);
  }
}

TEST_CASE("a saved file keeps the permissions of the file it replaces", "[io][atomic_file]") {
  const TempDir dir;
  const std::string path = dir.file("map.ivx");
  SparseBayes grid(0.1);
  fill_randomly(grid, 200, 3);
  for (const unsigned mode : {0600u, 0640u, 0604u, 0755u}) {
    save_text(path, "old");
    fs::permissions(path, static_cast<fs::perms>(mode), fs::perm_options::replace);
    save_grid(path, grid);
    CHECK(permissions_of(path) == mode);
    CHECK(load_grid<SparseBayes>(path).observed_count() == grid.observed_count());
  }
}

TEST_CASE("a new file gets 0666 minus the umask, as fopen creates it", "[io][atomic_file]") {
  const TempDir dir;
  const mode_t previous = ::umask(027);
  save_text(dir.file("new.txt"), "new");
  ::umask(previous);
  CHECK(permissions_of(dir.file("new.txt")) == 0640u);
}

TEST_CASE("a file with a long valid name saves", "[io][atomic_file]") {
  const TempDir dir;
  SparseBayes grid(0.1);
  fill_randomly(grid, 200, 4);
  for (const std::size_t length : {std::size_t{250}, std::size_t{NAME_MAX}}) {
    const std::string path = dir.file(std::string(length - 4, 'm') + ".ivx");
    save_grid(path, grid);
    CHECK(load_grid<SparseBayes>(path).observed_count() == grid.observed_count());
  }
  CHECK(count_files(dir.path()) == 2);
}

TEST_CASE("a save syncs the file before the rename and the folder after it", "[io][atomic_file]") {
  const TempDir dir;
  const std::string path = dir.file("map.txt");
  save_text(path, "old");
  const FsyncSpy spy;
  save_text(path, "new");
  const fs::path folder = fs::canonical(dir.path());
  REQUIRE(spy.paths().size() == 2);
  // The file is synced while it still has its temporary name, so before the rename.
  CHECK(fs::path(spy.paths()[0]).parent_path() == folder);
  CHECK(fs::path(spy.paths()[0]).filename().string().rfind(".ivx-", 0) == 0);
  CHECK(spy.paths()[1] == folder.string());
  CHECK(read_all(path) == "new");
}

TEST_CASE("a failed save leaves the old file byte-identical and no temporary", "[io][atomic_file]") {
  const TempDir dir;
  const std::string path = dir.file("map.ivx");
  SparseBayes grid(0.1);
  fill_randomly(grid, 300, 5);
  save_grid(path, grid);
  fs::permissions(path, fs::perms::owner_read | fs::perms::owner_write, fs::perm_options::replace);
  const std::string good = read_all(path);
  SparseBayes other(0.1);
  fill_randomly(other, 300, 6);
  SECTION("the data cannot be synced to the disk") {
    const FsyncSpy spy(EIO);
    CHECK_THROWS_WITH(save_grid(path, other), Catch::Contains(path) && Catch::Contains("I/O error"));
  }
  SECTION("the data cannot be synced, saving through a link") {
    fs::create_directory(dir.file("links"));
    const std::string link = dir.file("links/link.ivx");
    fs::create_symlink(path, link);
    const FsyncSpy spy(EIO);
    CHECK_THROWS_AS(save_grid(link, other), IoError);
    CHECK(fs::is_symlink(link));
    CHECK(count_files(dir.file("links")) == 1);
    fs::remove_all(dir.file("links"));
  }
  SECTION("the writer throws half-way") {
    CHECK_THROWS_WITH(detail::write_file_atomically(path,
                                                    [](std::FILE* f) {
                                                      std::fputs("half a file", f);
                                                      throw IoError("simulated failure in the middle of a write");
                                                    }),
                      Catch::Contains("simulated failure"));
  }
  CHECK(read_all(path) == good);
  CHECK(permissions_of(path) == 0600u);
  CHECK(count_files(dir.path()) == 1);
}

TEST_CASE("a save into a folder that cannot hold files is an error naming the path", "[io][atomic_file]") {
  const TempDir dir;
  save_text(dir.file("afile"), "a regular file");
  CHECK_THROWS_WITH(save_text(dir.file("afile/sub/map.ivx"), "new"), Catch::Contains("afile/sub/map.ivx"));
  CHECK_THROWS_WITH(save_text(dir.file("missing/map.ivx"), "new"), Catch::Contains("missing/map.ivx"));
  CHECK_THROWS_WITH(save_text(dir.path().string() + "/", "new"), Catch::Contains("names no file"));
  CHECK(read_all(dir.file("afile")) == "a regular file");
  CHECK(count_files(dir.path()) == 1);
}

TEST_CASE("the write-permission rule of a save is the kernel's for open(O_WRONLY)", "[io][atomic_file][permissions]") {
  struct stat st {};
  st.st_uid = 1000;
  st.st_gid = 100;
  const uid_t owner = 1000, member = 1001, other = 1002;
  const gid_t group = 100, foreign = 200;
  for (const unsigned mode : {0444u, 0644u, 0464u, 0446u, 0000u, 0222u}) {
    INFO("mode " << std::oct << mode);
    st.st_mode = S_IFREG | mode;
    CHECK(detail::mode_permits_write(st, owner, group, {}) == ((mode & 0200u) != 0));
    CHECK(detail::mode_permits_write(st, member, foreign, {group}) == ((mode & 0020u) != 0));
    CHECK(detail::mode_permits_write(st, member, group, {}) == ((mode & 0020u) != 0));
    CHECK(detail::mode_permits_write(st, other, foreign, {}) == ((mode & 0002u) != 0));
    CHECK(detail::mode_permits_write(st, 0, 0, {}));  // root writes anything, as with `echo x > file`
  }
  // The owner's bit decides for the owner even when group or others may write (as the kernel).
  st.st_mode = S_IFREG | 0466u;
  CHECK_FALSE(detail::mode_permits_write(st, owner, group, {group}));
}

TEST_CASE("saving through a link to a write-protected file is refused and changes nothing",
          "[io][atomic_file][permissions]") {
  const TempDir dir;
  save_text(dir.file("protected.html"), "precious");
  fs::permissions(dir.file("protected.html"), static_cast<fs::perms>(0444), fs::perm_options::replace);
  fs::create_symlink("protected.html", dir.file("link.html"));
  if (::geteuid() == 0) {
    // Root may write a 0444 file (the shell's `echo x > link.html` succeeds too), so the refusal
    // cannot be seen here; the rule itself is checked above through mode_permits_write.
    WARN("running as root: a 0444 file is writable for root; the refusal is checked through mode_permits_write only");
    save_text(dir.file("link.html"), "new");
    CHECK(read_all(dir.file("protected.html")) == "new");
    CHECK(permissions_of(dir.file("protected.html")) == 0444u);
    CHECK(fs::is_symlink(dir.file("link.html")));
    return;
  }
  CHECK_THROWS_WITH(save_text(dir.file("link.html"), "new"),
                    Catch::Contains("link.html") && Catch::Contains("write-protected") && Catch::Contains("0444"));
  CHECK_THROWS_WITH(save_text(dir.file("protected.html"), "new"), Catch::Contains("write-protected"));
  CHECK(read_all(dir.file("protected.html")) == "precious");
  CHECK(fs::is_symlink(dir.file("link.html")));
  CHECK(count_files(dir.path()) == 2);
}

namespace {

/// A UNIX socket bound at \p path (a socket file in the folder); closed on destruction.
class SocketFile {
 public:
  explicit SocketFile(const std::string& path) {
    fd_ = ::socket(AF_UNIX, SOCK_STREAM, 0);
    REQUIRE(fd_ >= 0);
    sockaddr_un addr{};
    addr.sun_family = AF_UNIX;
    REQUIRE(path.size() < sizeof addr.sun_path);
    std::copy(path.begin(), path.end(), addr.sun_path);
    REQUIRE(::bind(fd_, reinterpret_cast<const sockaddr*>(&addr), sizeof addr) == 0);
  }
  ~SocketFile() { ::close(fd_); }
  SocketFile(const SocketFile&) = delete;
  SocketFile& operator=(const SocketFile&) = delete;

 private:
  int fd_ = -1;
};

bool is_fifo(const std::string& path) {
  struct stat st {};
  return ::lstat(path.c_str(), &st) == 0 && S_ISFIFO(st.st_mode);
}

}  // namespace

TEST_CASE("a save onto a FIFO, a socket or a directory is refused, naming it, before anything is written",
          "[io][atomic_file]") {
  // Never the real /dev/null: as root, a save there would replace the system's device. A FIFO and
  // a socket in a temporary folder are files that are not regular files just as a device is.
  const TempDir dir;
  REQUIRE(::mkfifo(dir.file("pipe").c_str(), 0644) == 0);
  fs::create_directory(dir.file("folder"));
  fs::create_symlink("pipe", dir.file("link_to_pipe"));
  const std::string socket_path = dir.file("sock");
  const SocketFile socket(socket_path);
  // three.js stand-ins: write_html_view inlines whatever the folder holds.
  fs::create_directories(dir.file("three/build"));
  fs::create_directories(dir.file("three/examples/js/controls"));
  save_text(dir.file("three/build/three.min.js"), "/* three */");
  save_text(dir.file("three/examples/js/controls/OrbitControls.js"), "/* orbit */");
  HtmlViewOptions html;
  html.three_dir = dir.file("three");

  SparseBayes grid(0.1);
  fill_randomly(grid, 200, 9);
  const ExplainedSpace space(grid.geometry());
  struct Target {
    std::string path, kind;
  };
  const std::vector<Target> targets = {{dir.file("pipe"), "a FIFO"},
                                       {dir.file("link_to_pipe"), "a FIFO"},
                                       {socket_path, "a socket"},
                                       {dir.file("folder"), "a directory"}};
  for (const Target& t : targets) {
    INFO("target " << t.path);
    // (a matcher combined with && keeps references to its parts: spelled out in each check)
#define INTERVOX_REFUSED Catch::Contains(t.path) && Catch::Contains(t.kind) && Catch::Contains("not a regular file")
    CHECK_THROWS_WITH(save_grid(t.path, grid), INTERVOX_REFUSED);
    CHECK_THROWS_WITH(save_explained(t.path, space), INTERVOX_REFUSED);
    CHECK_THROWS_WITH(write_bt(t.path, grid), INTERVOX_REFUSED);
    CHECK_THROWS_WITH(write_ply(t.path, grid), INTERVOX_REFUSED);
    CHECK_THROWS_WITH(write_html_view(t.path, grid, html), INTERVOX_REFUSED);
    CHECK_THROWS_WITH(save_text(t.path, "x"), INTERVOX_REFUSED);
#undef INTERVOX_REFUSED
    CHECK_THROWS_AS(save_text(t.path, "x"), IoError);
  }
  // Nothing changed: the FIFO, the link, the folder and the socket are still there, and no
  // temporary was left beside them.
  CHECK(is_fifo(dir.file("pipe")));
  CHECK(fs::is_symlink(dir.file("link_to_pipe")));
  CHECK(fs::is_directory(dir.file("folder")));
  CHECK(fs::is_empty(dir.file("folder")));
  CHECK(fs::is_socket(socket_path));
  CHECK(count_files(dir.path()) == 5);  // pipe, link_to_pipe, sock, folder, three
}
