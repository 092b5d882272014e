#include "io/output_lock.hpp"

#include <fcntl.h>
#include <sys/file.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>

#include "crowddb/error.hpp"

namespace crowddb::io {

OutputLock::OutputLock(const std::filesystem::path& target) : lock_(target.string() + ".lock") {
  // The holder removes the file when it is done; a process that opened the file just before
  // that holds a lock on an unlinked inode, so check that the locked file is still the one on
  // disk, and try again otherwise.
  for (int attempt = 0; attempt < 16; ++attempt) {
    const int fd = ::open(lock_.c_str(), O_RDWR | O_CREAT | O_CLOEXEC, 0644);
    if (fd < 0)
      throw Error(Error::Kind::io, target.string() + ": cannot create the lock file " +
                                       lock_.string() + " (" + std::strerror(errno) + ")");
    if (::flock(fd, LOCK_EX | LOCK_NB) != 0) {
      const int err = errno;
      ::close(fd);
      if (err == EWOULDBLOCK)
        throw Error(Error::Kind::io, target.string() +
                                         ": another crowddb run is writing this output (" +
                                         lock_.string() + " is locked)");
      throw Error(Error::Kind::io, target.string() + ": cannot lock " + lock_.string() + " (" +
                                       std::strerror(err) + ")");
    }
    struct stat held {
    }, on_disk{};
    if (::fstat(fd, &held) == 0 && ::stat(lock_.c_str(), &on_disk) == 0 &&
        held.st_ino == on_disk.st_ino && held.st_dev == on_disk.st_dev) {
      fd_ = fd;
      return;
    }
    ::close(fd);  // removed (and perhaps re-created) meanwhile: the lock is worth nothing
  }
  throw Error(Error::Kind::io, target.string() + ": cannot lock " + lock_.string() +
                                   " (it keeps being replaced by other runs)");
}

OutputLock::~OutputLock() {
  release();
}

void OutputLock::release() noexcept {
  if (fd_ < 0) return;
  ::unlink(lock_.c_str());  // while still holding the lock: see the constructor
  ::close(fd_);
  fd_ = -1;
}

}  // namespace crowddb::io
