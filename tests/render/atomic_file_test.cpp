// AtomicFile: every live temporary goes on a signal, and a set of files is committed all or none
// (a full disk on one leaves neither).
#include "atomic_file.h"

#include <fcntl.h>
#include <gtest/gtest.h>
#include <unistd.h>

#include <csignal>
#include <filesystem>
#include <fstream>
#include <memory>
#include <stdexcept>
#include <string>
#include <vector>

namespace {

namespace fs = std::filesystem;
using hamiltone::cli::AtomicFile;
using hamiltone::cli::commitTogether;

class AtomicFileTest : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::temp_directory_path() /
           ("hamiltone-atomic-" + std::to_string(::getpid()) + "-" +
            ::testing::UnitTest::GetInstance()->current_test_info()->name());
    fs::remove_all(dir_);
    fs::create_directories(dir_);
  }
  void TearDown() override { fs::remove_all(dir_); }

  std::string path(const std::string& name) const { return (dir_ / name).string(); }
  std::vector<std::string> listing() const {
    std::vector<std::string> names;
    for (const auto& entry : fs::directory_iterator(dir_)) names.push_back(entry.path().filename());
    return names;
  }
  static std::string slurp(const std::string& p) {
    std::ifstream in(p);
    return std::string(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
  }

  fs::path dir_;
};

// Writes to `file` fail as on a full disk from now on: its descriptor becomes /dev/full.
bool makeFull(AtomicFile& file) {
  const int full = ::open("/dev/full", O_WRONLY);
  if (full < 0) return false;
  const bool ok = ::dup2(full, fileno(file.stream())) >= 0;
  ::close(full);
  return ok;
}

// Three temporaries open, one with data, then `signal`.
void threeOpenThenSignal(const fs::path& dir, int signal) {
  AtomicFile a((dir / "a.csv").string(), "--out");
  AtomicFile b((dir / "b.csv").string(), "--snapshot-out");
  AtomicFile c((dir / "c.csv").string(), "--other");
  std::fputs("data\n", a.stream());
  std::fflush(a.stream());
  std::raise(signal);
}

// One temporary made and removed (its slot freed), then two open, then `signal`.
void reusedSlotThenSignal(const fs::path& dir, int signal) {
  { AtomicFile first((dir / "first.csv").string(), "--out"); }
  AtomicFile a((dir / "a.csv").string(), "--out");
  AtomicFile b((dir / "b.csv").string(), "--snapshot-out");
  std::raise(signal);
}

TEST_F(AtomicFileTest, SignalRemovesEveryLiveTemporary) {
  EXPECT_EXIT(threeOpenThenSignal(dir_, SIGTERM), ::testing::ExitedWithCode(128 + SIGTERM), "");
  EXPECT_TRUE(listing().empty());
  EXPECT_EXIT(reusedSlotThenSignal(dir_, SIGINT), ::testing::ExitedWithCode(128 + SIGINT), "");
  EXPECT_TRUE(listing().empty());
}

TEST_F(AtomicFileTest, CommitTogetherPublishesEveryFile) {
  AtomicFile a(path("a.csv"), "--out"), b(path("b.csv"), "--snapshot-out");
  std::fputs("a\n", a.stream());
  std::fputs("b\n", b.stream());
  commitTogether({&a, nullptr, &b});
  EXPECT_EQ(slurp(path("a.csv")), "a\n");
  EXPECT_EQ(slurp(path("b.csv")), "b\n");
  EXPECT_EQ(listing().size(), 2u);
}

TEST_F(AtomicFileTest, AFullDiskOnOneFilePublishesNeither) {
  for (const int failing : {0, 1}) {
    { std::ofstream(path("a.csv")) << "old a\n"; }
    {
      AtomicFile a(path("a.csv"), "--out"), b(path("b.csv"), "--snapshot-out");
      AtomicFile* files[] = {&a, &b};
      if (!makeFull(*files[failing])) GTEST_SKIP() << "no /dev/full";
      std::fputs("new a\n", a.stream());
      std::fputs("new b\n", b.stream());
      EXPECT_THROW(commitTogether({&a, &b}), std::runtime_error) << failing;
    }
    EXPECT_EQ(slurp(path("a.csv")), "old a\n") << failing;  // untouched
    EXPECT_EQ(listing(), std::vector<std::string>{"a.csv"}) << failing;
    fs::remove(path("a.csv"));
  }
}

TEST_F(AtomicFileTest, AFinishedFileIsOnlyPublishedOnRequest) {
  {
    AtomicFile a(path("a.csv"), "--out");
    std::fputs("a\n", a.stream());
    a.finish();
    EXPECT_EQ(listing().size(), 1u);  // the temporary
  }
  EXPECT_TRUE(listing().empty());
  AtomicFile b(path("b.csv"), "--out");
  EXPECT_THROW(b.publish(), std::logic_error);
  b.commit();
  EXPECT_EQ(listing(), std::vector<std::string>{"b.csv"});
}

TEST_F(AtomicFileTest, TooManyAtOnceIsAnErrorThatLeavesNoTemporary) {
  {
    std::vector<std::unique_ptr<AtomicFile>> files;
    for (int i = 0; i < AtomicFile::kMaxLive; ++i)
      files.push_back(std::make_unique<AtomicFile>(path(std::to_string(i)), "--out"));
    EXPECT_THROW(AtomicFile(path("one-more"), "--out"), std::runtime_error);
    EXPECT_EQ(listing().size(), static_cast<size_t>(AtomicFile::kMaxLive));
  }
  EXPECT_TRUE(listing().empty());
  AtomicFile again(path("again"), "--out");  // the slots were released
  again.commit();
}

}  // namespace
