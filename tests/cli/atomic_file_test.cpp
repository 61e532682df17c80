// AtomicFile: every live temporary goes on a signal, and a set of files is committed all or none
// (a full disk on one leaves neither).
#include "atomic_file.h"

#include <fcntl.h>
#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <csignal>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <memory>
#include <stdexcept>
#include <string>
#include <vector>

#include "support/scratch_dir.h"
#include "usage_error.h"

namespace {

namespace fs = std::filesystem;
using hamiltone::cli::AtomicFile;
using hamiltone::cli::commitTogether;

class AtomicFileTest : public ::testing::Test {
 protected:
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

  hamiltone::testing::ScratchDir scratch_{"hamiltone-atomic"};
  const fs::path dir_ = scratch_.path();
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
  EXPECT_EXIT(threeOpenThenSignal(dir_, SIGTERM), ::testing::ExitedWithCode(128 + SIGTERM),
              ": stopped by SIGTERM; its unfinished output removed");
  EXPECT_TRUE(listing().empty());
  EXPECT_EXIT(reusedSlotThenSignal(dir_, SIGINT), ::testing::ExitedWithCode(128 + SIGINT), "");
  EXPECT_TRUE(listing().empty());
}

// Every signal sent to end the program removes the temporaries, not only the usual three: a stray
// SIGUSR1, a SIGPIPE from a closed pipe, a timeout's SIGALRM, Ctrl-\'s SIGQUIT, SIGPWR, the
// real-time signals.
TEST_F(AtomicFileTest, EverySignalThatWouldEndTheProgramRemovesTheTemporaries) {
  for (const int signal : AtomicFile::endingSignals()) {
    EXPECT_EXIT(threeOpenThenSignal(dir_, signal), ::testing::ExitedWithCode(128 + signal), "")
        << ::strsignal(signal);
    EXPECT_TRUE(listing().empty()) << ::strsignal(signal);
  }
}

// A signal that comes while the files are renamed into place (here: already pending when the
// renaming begins, held back on this thread) is too late to stop the run: taken, it leaves the
// run to end as it would have, with every file in place. When a rename fails, the same signal
// ends the run as any other: exit 128 + N, no temporary left.
void signalWhileRenaming(const fs::path& dir, bool renameFails) {
  AtomicFile a((dir / "a.csv").string(), "--out");
  AtomicFile b((dir / "b.csv").string(), "--snapshot-out");
  std::fputs("a\n", a.stream());
  std::fputs("b\n", b.stream());
  if (renameFails) fs::create_directory(dir / "b.csv");  // rename(2) onto a directory fails
  sigset_t term;
  sigemptyset(&term);
  sigaddset(&term, SIGTERM);
  ::pthread_sigmask(SIG_BLOCK, &term, nullptr);
  std::raise(SIGTERM);
  try {
    commitTogether({&a, &b});
  } catch (const std::runtime_error&) {
    ::pthread_sigmask(SIG_UNBLOCK, &term, nullptr);  // the signal, still pending, ends it here
    std::_Exit(99);
  }
  ::pthread_sigmask(SIG_UNBLOCK, &term, nullptr);
  std::_Exit(0);
}

TEST_F(AtomicFileTest, ASignalThatComesWhileTheFilesAreRenamedDoesNotUndoThem) {
  EXPECT_EXIT(signalWhileRenaming(dir_, false), ::testing::ExitedWithCode(0), "");
  EXPECT_EQ(slurp(path("a.csv")), "a\n");
  EXPECT_EQ(slurp(path("b.csv")), "b\n");
  fs::remove(path("a.csv"));
  fs::remove(path("b.csv"));
  EXPECT_EXIT(signalWhileRenaming(dir_, true), ::testing::ExitedWithCode(128 + SIGTERM), "");
  EXPECT_EQ(listing(), std::vector<std::string>{"b.csv"});  // the directory; a.csv removed again
  EXPECT_TRUE(fs::is_directory(path("b.csv")));
}

// Two players recording to one path: the second to finish replaced the first's take, both saying
// "recorded". With keepOthers (the recorder's) a file another program wrote at the path meanwhile
// is kept and this one goes beside it (NAME-2.EXT, then -3 …), whether the path was free at the
// start or held an older file; an older file nobody touched is replaced, as it always was; and
// without keepOthers (a render) the last to publish replaces as before.
TEST_F(AtomicFileTest, ARecordingKeepsAFileAnotherProgramWroteMeanwhile) {
  const std::string take = path("take.wav");
  auto write = [](const std::string& p, const char* text) { std::ofstream(p) << text; };
  auto publish = [](AtomicFile& f, const char* text) {
    std::fputs(text, f.stream());
    f.commit();
  };
  {  // free at the start, written meanwhile
    AtomicFile mine(take, "--record", true);
    write(take, "theirs");
    publish(mine, "mine");
    EXPECT_TRUE(mine.movedAside());
    EXPECT_EQ(mine.path(), path("take-2.wav"));
  }
  EXPECT_EQ(slurp(take), "theirs");
  EXPECT_EQ(slurp(path("take-2.wav")), "mine");
  {  // an older file there, rewritten meanwhile (another size): -2 is taken, so -3
    AtomicFile mine(take, "--record", true);
    write(take, "theirs, again");
    publish(mine, "mine again");
    EXPECT_EQ(mine.path(), path("take-3.wav"));
  }
  EXPECT_EQ(slurp(take), "theirs, again");
  EXPECT_EQ(slurp(path("take-3.wav")), "mine again");
  {  // an older file nobody touched: replaced
    AtomicFile mine(take, "--record", true);
    publish(mine, "a new take");
    EXPECT_FALSE(mine.movedAside());
  }
  EXPECT_EQ(slurp(take), "a new take");
  {  // a render: the last to publish replaces
    AtomicFile out(take, "-o");
    write(take, "theirs");
    publish(out, "rendered");
    EXPECT_FALSE(out.movedAside());
  }
  EXPECT_EQ(slurp(take), "rendered");
  EXPECT_EQ(listing().size(), 3u);  // take, take-2, take-3: no temporary
}

// A signal ignored by whoever started the program (nohup, trap '' HUP) stays ignored: the run
// goes on and its file appears. A signal not ignored still removes the temporaries.
void ignoredHangupThenCommit(const fs::path& dir) {
  std::signal(SIGHUP, SIG_IGN);
  AtomicFile a((dir / "a.csv").string(), "--out");
  std::fputs("data\n", a.stream());
  std::raise(SIGHUP);
  a.commit();
  std::raise(SIGUSR1);  // handled: ends the child, which removes nothing now (all published)
}

TEST_F(AtomicFileTest, AnInheritedIgnoreIsKept) {
  EXPECT_EXIT(ignoredHangupThenCommit(dir_), ::testing::ExitedWithCode(128 + SIGUSR1), "");
  EXPECT_EQ(slurp(path("a.csv")), "data\n");
  EXPECT_EQ(listing(), std::vector<std::string>{"a.csv"});
}

// A run killed by SIGKILL cannot clean up: its temporary, named after its PID, is removed by the
// next run that writes the same file once that PID is gone — and only then: a temporary of a
// live process (here this test's own PID), or another file, is left alone.
void openThenKill(const fs::path& dir) {
  AtomicFile a((dir / "a.wav").string(), "-o");
  std::fputs("half a take", a.stream());
  std::fflush(a.stream());
  std::raise(SIGKILL);
}

TEST_F(AtomicFileTest, ATemporaryLeftBySigkillIsRemovedByTheNextRun) {
  EXPECT_EXIT(openThenKill(dir_), ::testing::KilledBySignal(SIGKILL), "");
  ASSERT_EQ(listing().size(), 1u);
  const std::string stale = listing().front();
  EXPECT_TRUE(stale.starts_with("a.wav.tmp-")) << stale;
  const std::string live = "a.wav.tmp-" + std::to_string(::getpid()) + "-abcdef";
  { std::ofstream(path(live)) << "a live run's"; }
  { std::ofstream(path("a.wav.tmp-notes.txt")) << "someone's"; }
  AtomicFile again(path("a.wav"), "-o");
  std::fputs("whole", again.stream());
  again.commit();
  std::vector<std::string> names = listing();
  std::sort(names.begin(), names.end());
  std::vector<std::string> kept = {"a.wav", "a.wav.tmp-notes.txt", live};
  std::sort(kept.begin(), kept.end());
  EXPECT_EQ(names, kept);
  EXPECT_EQ(slurp(path("a.wav")), "whole");
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
      // The write's own error: /dev/full also refuses the fsync that follows (EINVAL), which
      // alone would throw too.
      try {
        commitTogether({&a, &b});
        ADD_FAILURE() << "no error, " << failing;
      } catch (const std::runtime_error& e) {
        EXPECT_THAT(e.what(), ::testing::HasSubstr(std::strerror(ENOSPC))) << failing;
      }
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

// A symlink to nothing is neither followed (that would create a file wherever it points) nor
// replaced (the link may be what someone meant to keep): refused, naming the flag and the link.
TEST_F(AtomicFileTest, ADanglingSymlinkIsRefusedAndKept) {
  fs::create_symlink(dir_ / "missing.csv", dir_ / "link.csv");
  try {
    AtomicFile file(path("link.csv"), "--out");
    FAIL() << "expected UsageError";
  } catch (const hamiltone::cli::UsageError& e) {
    EXPECT_NE(std::string(e.what()).find("--out = " + path("link.csv")), std::string::npos)
        << e.what();
    EXPECT_NE(std::string(e.what()).find("does not exist"), std::string::npos) << e.what();
  }
  EXPECT_TRUE(fs::is_symlink(dir_ / "link.csv"));
  EXPECT_EQ(listing(), std::vector<std::string>{"link.csv"});
  // A link to an existing file is followed: the file is replaced, the link kept.
  { std::ofstream(path("target.csv")) << "old\n"; }
  fs::remove(dir_ / "link.csv");
  fs::create_symlink(dir_ / "target.csv", dir_ / "link.csv");
  AtomicFile file(path("link.csv"), "--out");
  std::fputs("new\n", file.stream());
  file.commit();
  EXPECT_TRUE(fs::is_symlink(dir_ / "link.csv"));
  EXPECT_EQ(slurp(path("target.csv")), "new\n");
}

// An output that is one of the inputs — by the same path, another spelling or a link — is refused
// naming both flags; a different file, or an input not given (empty), is not.
TEST_F(AtomicFileTest, AnInputAsOutputIsRefused) {
  using hamiltone::cli::refuseInputAsOutput;
  { std::ofstream(path("in.toml")) << "x\n"; }
  fs::create_symlink(dir_ / "in.toml", dir_ / "link.wav");
  const std::vector<hamiltone::cli::InputFile> inputs = {{"--midi", ""},
                                                         {"--preset", path("in.toml")}};
  for (const std::string& out :
       {path("in.toml"), (dir_ / "." / "in.toml").string(), path("link.wav")}) {
    try {
      refuseInputAsOutput("-o", out, inputs);
      ADD_FAILURE() << out << ": expected UsageError";
    } catch (const hamiltone::cli::UsageError& e) {
      EXPECT_NE(std::string(e.what()).find("-o = " + out), std::string::npos) << e.what();
      EXPECT_NE(std::string(e.what()).find("--preset = " + path("in.toml")), std::string::npos)
          << e.what();
    }
  }
  EXPECT_NO_THROW(refuseInputAsOutput("-o", path("out.wav"), inputs));
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
