// One writer per output: a run holds an exclusive lock on PATH.lock while it writes PATH (and
// PATH.partial), so a second run with the same --out stops at once with a message instead of
// deleting the first run's file under it. flock() locks go with the process: a run killed
// with kill -9 leaves no stale lock (the .lock file may stay; it is unlocked).
#pragma once

#include <filesystem>

namespace crowddb::io {

class OutputLock {
 public:
  // Locks PATH.lock for `target`; throws Error(io) naming the output when another process
  // holds it or the lock file cannot be created.
  explicit OutputLock(const std::filesystem::path& target);
  ~OutputLock();
  OutputLock(const OutputLock&) = delete;
  OutputLock& operator=(const OutputLock&) = delete;

  // Removes the lock file and releases the lock (also done by the destructor).
  void release() noexcept;

 private:
  std::filesystem::path lock_;
  int fd_ = -1;
};

}  // namespace crowddb::io
