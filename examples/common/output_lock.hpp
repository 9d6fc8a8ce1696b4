#pragma once
// One run per output folder: a program that writes a folder of results (experiments,
// mobile_exploration) takes the folder's lock first, so that a second run into the same folder is
// refused with a clear message instead of mixing or overwriting the first run's files.
//
// The lock is an flock(2) on the file `.intervox-run.lock` in the folder, which holds the pid of
// the run that holds the lock (for the message). The run removes the file when it ends normally;
// the kernel releases the lock when it ends in any way (exit, crash, kill), so a file left by a
// crashed run does not block later runs. A run that locked a file another run removed meanwhile
// retries on the new file, so two runs never hold the lock at once. flock locks are advisory and
// may not work across NFS clients; POSIX only.
#include <intervox/core/error.hpp>

#include <fcntl.h>
#include <sys/file.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <string>

namespace examples {

/// Holds the lock of an output folder for its lifetime (see the file comment).
class OutputFolderLock {
 public:
  static constexpr const char* kFileName = ".intervox-run.lock";

  /// Creates \p folder as needed and takes its lock.
  /// \throws intervox::IoError "output folder F is in use by another run (pid N)" if another run
  ///   holds it, or naming the folder if it cannot be created or locked;
  ///   std::filesystem::filesystem_error if the folder cannot be created.
  explicit OutputFolderLock(const std::string& folder) {
    std::filesystem::create_directories(folder);
    path_ = (std::filesystem::path(folder) / kFileName).string();
    // Retry when the file was removed by the run that held it between our open and our flock:
    // the lock must be on the file that the path names now.
    for (int attempt = 0;; ++attempt) {
      fd_ = ::open(path_.c_str(), O_RDWR | O_CREAT | O_CLOEXEC, 0644);
      if (fd_ < 0) {
        throw intervox::IoError("cannot lock the output folder " + folder + ": cannot open " + path_ + ": " +
                                std::strerror(errno));
      }
      if (::flock(fd_, LOCK_EX | LOCK_NB) != 0) {
        const int error = errno;
        char buf[32] = {};
        const ssize_t n = ::pread(fd_, buf, sizeof buf - 1, 0);
        ::close(fd_);
        fd_ = -1;
        if (error == EWOULDBLOCK) {
          const long pid = n > 0 ? std::strtol(buf, nullptr, 10) : 0;
          throw intervox::IoError("output folder " + folder + " is in use by another run" +
                                  (pid > 0 ? " (pid " + std::to_string(pid) + ")" : std::string()) +
                                  "; wait for it to end or choose another --out");
        }
        throw intervox::IoError("cannot lock the output folder " + folder + ": " + std::strerror(error));
      }
      struct stat held {
      }, named{};
      if (::fstat(fd_, &held) == 0 && ::stat(path_.c_str(), &named) == 0 && held.st_ino == named.st_ino &&
          held.st_dev == named.st_dev) {
        break;
      }
      ::close(fd_);
      fd_ = -1;
      if (attempt == 100)
        throw intervox::IoError("cannot lock the output folder " + folder + ": its lock file keeps changing");
    }
    const std::string pid = std::to_string(::getpid()) + "\n";
    if (::ftruncate(fd_, 0) != 0 || ::pwrite(fd_, pid.data(), pid.size(), 0) != static_cast<ssize_t>(pid.size())) {
      // The lock is held; only the pid in the message of a competing run is missing.
    }
  }
  /// Removes the lock file (while still holding the lock) and releases the lock.
  ~OutputFolderLock() {
    if (fd_ >= 0) {
      ::unlink(path_.c_str());
      ::close(fd_);
    }
  }
  OutputFolderLock(const OutputFolderLock&) = delete;
  OutputFolderLock& operator=(const OutputFolderLock&) = delete;

 private:
  std::string path_;
  int fd_ = -1;
};

}  // namespace examples
