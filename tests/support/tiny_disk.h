// A full disk for tests of what a program does when a write fails: a tiny tmpfs, mounted by the
// test where it may (as root), so that no fault needs injecting into the code under test.
#pragma once

#include <sys/mount.h>
#include <unistd.h>

#include <filesystem>

namespace hamiltone::test {

// A full disk to write to: a 64 KiB tmpfs mounted on `dir` while alive. Needs root (or
// CAP_SYS_ADMIN); mounted() is false where that fails, and the test should skip.
class TinyDisk {
 public:
  explicit TinyDisk(const std::filesystem::path& dir) : dir_(dir) {
    std::filesystem::create_directories(dir_);
    mounted_ = ::geteuid() == 0 && ::mount("tmpfs", dir_.c_str(), "tmpfs", 0, "size=64k") == 0;
  }
  ~TinyDisk() {
    if (mounted_) ::umount2(dir_.c_str(), MNT_DETACH);
  }
  TinyDisk(const TinyDisk&) = delete;
  TinyDisk& operator=(const TinyDisk&) = delete;
  bool mounted() const { return mounted_; }

 private:
  std::filesystem::path dir_;
  bool mounted_ = false;
};

}  // namespace hamiltone::test
