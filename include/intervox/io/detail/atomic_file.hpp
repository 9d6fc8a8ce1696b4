#pragma once
/// \file
/// Internal: how every writer of the io layer saves a file. The bytes go into an exclusive
/// temporary file in the target's directory, which is synced and renamed onto the target, so a
/// failed or concurrent write never leaves a half-written file in place of a good one. Not part of
/// the public API; docs/io.md ("Saving safely") describes the behaviour users see. POSIX only.

#include <intervox/core/error.hpp>
#include <intervox/core/path.hpp>
#include <intervox/io/detail/binary.hpp>

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <cerrno>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <random>
#include <string>
#include <system_error>
#include <vector>

namespace intervox::detail {

/// The most symbolic links followed from a saved path before giving up (Linux's limit).
inline constexpr int kMaxSaveLinks = 40;

/// The file that a save to `path` replaces: `path` itself or, when `path` is a symbolic link (or a
/// chain of them), the file the last link names. That file need not exist yet: saving to a
/// dangling link creates its target, as `echo > link` does.
/// \throws IoError for a loop of links or a link that cannot be read.
inline std::filesystem::path save_target(const std::string& path) {
  namespace fs = std::filesystem;
  check_path(path);  // a NUL would make the save write another, shorter name
  fs::path target(path);
  for (int links = 0;; ++links) {
    std::error_code ec;
    if (!fs::is_symlink(fs::symlink_status(target, ec))) return target;
    if (links == kMaxSaveLinks) throw IoError("cannot save '" + path + "': too many levels of symbolic links");
    const fs::path next = fs::read_symlink(target, ec);
    if (ec)
      throw IoError("cannot save '" + path + "': cannot read the link '" + target.string() + "': " + ec.message());
    target = next.is_absolute() ? next : target.parent_path() / next;
  }
}

/// True if a user with effective uid `euid`, effective gid `egid` and supplementary `groups` may
/// write a file of status `st` by its permission bits, as the kernel decides for `open(O_WRONLY)`
/// (and so as the shell decides for `echo x > file`): root (euid 0) always; the owner by the owner
/// bit; a member of the file's group by the group bit; anyone else by the "other" bit. ACLs are not
/// consulted.
inline bool mode_permits_write(const struct stat& st, uid_t euid, gid_t egid,
                               const std::vector<gid_t>& groups) noexcept {
  if (euid == 0) return true;
  if (st.st_uid == euid) return (st.st_mode & S_IWUSR) != 0;
  const bool member = st.st_gid == egid || std::find(groups.begin(), groups.end(), st.st_gid) != groups.end();
  if (member) return (st.st_mode & S_IWGRP) != 0;
  return (st.st_mode & S_IWOTH) != 0;
}

/// mode_permits_write for the calling process (its effective uid, gid and supplementary groups).
inline bool process_may_write(const struct stat& st) {
  std::vector<gid_t> groups(static_cast<std::size_t>(std::max(0, ::getgroups(0, nullptr))));
  if (!groups.empty())
    groups.resize(static_cast<std::size_t>(std::max(0, ::getgroups(static_cast<int>(groups.size()), groups.data()))));
  return mode_permits_write(st, ::geteuid(), ::getegid(), groups);
}

/// A new, empty temporary file in `dir` named `.ivx-` and ten random characters: short, so a valid
/// target name of any length saves, and hidden, so globs of the folder do not see it. Created with
/// O_CREAT | O_EXCL (never shared with another thread or process) and mode 0666 before the umask,
/// as fopen creates files. Returns the descriptor and sets `name` to the file's path.
/// \throws IoError naming `path` when no temporary can be created in `dir`.
inline int create_temporary(const std::filesystem::path& dir, const std::string& path, std::string& name) {
  static constexpr char kAlphabet[] = "abcdefghijklmnopqrstuvwxyz0123456789";
  static std::atomic<std::uint64_t> counter{0};
  std::random_device device;
  std::uint64_t state = (static_cast<std::uint64_t>(device()) << 32) ^ device() ^
                        (static_cast<std::uint64_t>(::getpid()) << 20) ^ counter.fetch_add(1);
  for (int attempt = 0; attempt < 100; ++attempt) {
    std::string leaf = ".ivx-";
    for (int i = 0; i < 10; ++i) {
      state = state * 6364136223846793005ULL + 1442695040888963407ULL;  // Knuth's MMIX LCG
      leaf += kAlphabet[(state >> 33) % (sizeof kAlphabet - 1)];
    }
    name = (dir / leaf).string();
    const int fd = ::open(name.c_str(), O_WRONLY | O_CREAT | O_EXCL | O_CLOEXEC, 0666);
    if (fd >= 0) return fd;
    if (errno != EEXIST) {
      throw IoError("cannot create a temporary file in '" + dir.string() + "' to save '" + path +
                    "': " + std::strerror(errno));
    }
  }
  throw IoError("cannot create a temporary file in '" + dir.string() + "' to save '" + path +
                "': every name tried exists");
}

/// What a save to a path replaces, found and checked before anything is written
/// (check_save_target()).
struct SaveTarget {
  std::filesystem::path target;  ///< the file replaced: the path, or a link's final target
  std::filesystem::path dir;     ///< its folder, where the temporary goes
  bool replaces = false;         ///< the file exists
  struct stat old {};            ///< its status, when it exists
};

/// The checks write_file_atomically() makes before it writes anything, alone, for savers of several
/// files that refuse all of them before writing the first: the path names a file (through links,
/// save_target()); the file it would replace, if it exists, is a regular file (not a directory,
/// device, FIFO or socket) that the process may write by its permission bits.
/// \throws IoError naming the path (and the link's target for a link) and the problem.
inline SaveTarget check_save_target(const std::string& path) {
  namespace fs = std::filesystem;
  if (path.empty()) throw IoError("cannot write a file with an empty path");
  SaveTarget t;
  t.target = save_target(path);
  if (!t.target.has_filename()) throw IoError("cannot write '" + path + "': the path names no file");
  t.dir = t.target.has_parent_path() ? t.target.parent_path() : fs::path(".");
  t.replaces = ::stat(t.target.c_str(), &t.old) == 0;
  const std::string shown =
      "'" + path + "'" + (t.target.string() != path ? " (a link to '" + t.target.string() + "')" : std::string());
  if (t.replaces && !S_ISREG(t.old.st_mode))
    throw IoError("cannot write " + shown + ": it is " + file_kind(t.old.st_mode) +
                  ", not a regular file (a save replaces regular files only)");
  if (t.replaces && !process_may_write(t.old)) {
    char mode[8];
    std::snprintf(mode, sizeof mode, "%04o", static_cast<unsigned>(t.old.st_mode & 07777));
    throw IoError("cannot write " + shown + ": the file is write-protected (mode " + mode + "): Permission denied");
  }
  return t;
}

/// Saves a file: calls `write(FILE*)` on a new exclusive temporary file in the directory of the
/// file `path` names (through symbolic links, see save_target), gives it the permission bits of the
/// file it replaces (a new file gets 0666 minus the umask), flushes and fsyncs it, renames it onto
/// that file and fsyncs the directory. A save honours the permissions of the file it replaces as
/// the shell does: if that file (the link's target, for a link) exists and the process may not
/// write it (mode_permits_write: a 0444 file for its owner, say), the save is refused before
/// anything is written, although the rename would be allowed by the folder's permissions. A save
/// replaces regular files only: if that file exists and is a directory, a device (/dev/null), a
/// FIFO or a socket, the save is refused before anything is written (the rename would otherwise
/// put a regular file in place of the device, which as root is allowed). Concurrent saves to one path, from threads or
/// processes, leave one complete file of one of them. On any failure before the rename (an exception from `write`, a
/// short write, a failing flush, sync, close or rename) the temporary is removed, the old file is left byte-identical
/// and IoError is thrown naming the path (an exception from `write` is rethrown as it is). \throws IoError as above
/// (naming the path, and the link's target for a link), and when the
///   directory cannot be synced after the rename (the file is then replaced, but may not survive a
///   power loss).
template <class Write>
void write_file_atomically(const std::string& path, Write&& write) {
  const SaveTarget checked = check_save_target(path);
  const std::filesystem::path& target = checked.target;
  const std::filesystem::path& dir = checked.dir;
  const bool replaces = checked.replaces;
  const struct stat& old = checked.old;

  std::string tmp;
  const int fd = create_temporary(dir, path, tmp);
  auto fail = [&](const std::string& what, int error) {
    ::unlink(tmp.c_str());
    throw IoError(what + ": " + std::strerror(error));
  };
  if (replaces && ::fchmod(fd, old.st_mode & 07777) != 0) {
    const int error = errno;
    ::close(fd);
    fail("cannot give the new '" + path + "' the permissions of the old one", error);
  }
  std::FILE* file = ::fdopen(fd, "wb");
  if (file == nullptr) {
    const int error = errno;
    ::close(fd);
    fail("cannot write '" + path + "'", error);
  }
  try {
    write(file);
  } catch (...) {
    std::fclose(file);
    ::unlink(tmp.c_str());
    throw;
  }
  errno = EIO;  // ferror does not set errno
  bool failed = std::ferror(file) != 0 || std::fflush(file) != 0 || ::fsync(::fileno(file)) != 0;
  int error = errno;
  if (std::fclose(file) != 0 && !failed) {
    failed = true;
    error = errno;
  }
  if (failed) fail("writing '" + path + "' failed (disk full or I/O error)", error);
  if (::rename(tmp.c_str(), target.c_str()) != 0) fail("cannot move the written file onto '" + path + "'", errno);

  // The rename is durable only once the directory is synced. A directory that cannot be opened for
  // reading cannot be synced; a file system that cannot sync directories says EINVAL.
  const int dir_fd = ::open(dir.c_str(), O_RDONLY | O_DIRECTORY | O_CLOEXEC);
  if (dir_fd >= 0) {
    const int synced = ::fsync(dir_fd);
    const int dir_error = errno;
    ::close(dir_fd);
    if (synced != 0 && dir_error != EINVAL) {
      throw IoError("'" + path + "' was written, but syncing its folder '" + dir.string() +
                    "' failed: " + std::strerror(dir_error));
    }
  }
}

/// Writes `size` bytes or throws IoError naming `path`.
inline void write_bytes(std::FILE* file, const void* data, std::size_t size, const std::string& path) {
  if (size != 0 && std::fwrite(data, 1, size, file) != size) {
    throw IoError("writing '" + path + "' failed (disk full or I/O error)");
  }
}

}  // namespace intervox::detail
