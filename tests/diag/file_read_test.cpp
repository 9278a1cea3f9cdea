#include "diag/file_read.h"

#include <gtest/gtest.h>
#include <sys/stat.h>
#include <unistd.h>

#include <csignal>
#include <filesystem>
#include <fstream>
#include <string>
#include <thread>

#include "diag/number.h"
#include "support/scratch_dir.h"

namespace fs = std::filesystem;
using eamos::diag::FileRead;
using eamos::diag::Pipes;
using eamos::diag::read_bounded_file;

namespace {

std::string file_in(const eamos_test::ScratchDir& dir, const std::string& name, const std::string& text) {
  std::ofstream(dir / name, std::ios::binary) << text;
  return dir / name;
}

}  // namespace

TEST(FileRead, ARegularFileIsReadWhole) {
  eamos_test::ScratchDir s("file-read");
  std::string text;
  FileRead r = read_bounded_file(file_in(s, "a.txt", "one\ntwo\n"), 100, text);
  EXPECT_EQ(r.status, FileRead::ok) << r.detail;
  EXPECT_EQ(text, "one\ntwo\n");
}

TEST(FileRead, ADeviceIsRefusedWithoutReadingIt) {
  std::string text;
  FileRead r = read_bounded_file("/dev/zero", 1 << 20, text, Pipes::read);
  EXPECT_EQ(r.status, FileRead::not_regular);
  EXPECT_EQ(r.detail, "a character device");
  EXPECT_TRUE(text.empty());
  EXPECT_EQ(eamos::diag::describe(r, 1 << 20), "a character device, not a regular file");
  EXPECT_EQ(eamos::diag::why_not_readable("/dev/zero", Pipes::read), "a character device, not a regular file");
}

TEST(FileRead, AFileLargerThanTheBoundIsRefusedAndSaysBoth) {
  eamos_test::ScratchDir s("file-read");
  std::string text;
  FileRead r = read_bounded_file(file_in(s, "big.txt", std::string(2000, 'x')), 1024, text);
  EXPECT_EQ(r.status, FileRead::too_large);
  EXPECT_EQ(eamos::diag::describe(r, 1024), "2000 bytes, more than the 1024 bytes it may hold");
  EXPECT_EQ(eamos::diag::describe({FileRead::too_large, "3000000"}, 2 << 20),
            "3000000 bytes, more than the 2097152 bytes (2 MiB) it may hold");
}

TEST(FileRead, AMissingFileGivesTheSystemsReason) {
  std::string text;
  FileRead r = read_bounded_file("/nonexistent/eamos", 100, text);
  EXPECT_EQ(r.status, FileRead::cannot_open);
  EXPECT_EQ(r.detail, "No such file or directory");
}

// A FIFO whose writer comes later is waited for and read to its end when pipes are read, and
// refused at once (without waiting for a writer) when they are not.
TEST(FileRead, AFifoIsReadToItsEndOnlyWhenPipesAreRead) {
  eamos_test::ScratchDir s("file-read");
  std::string fifo = s / "fifo";
  ASSERT_EQ(mkfifo(fifo.c_str(), 0600), 0);
  std::string text;
  FileRead refused = read_bounded_file(fifo, 100, text, Pipes::refused);
  EXPECT_EQ(refused.status, FileRead::not_regular);
  EXPECT_EQ(refused.detail, "a FIFO");
  // The writer opens, writes and closes before or after the reader starts to wait: both read it.
  std::thread writer([&] { std::ofstream(fifo) << "from the writer\n"; });
  FileRead read = read_bounded_file(fifo, 100, text, Pipes::read);
  writer.join();
  EXPECT_EQ(read.status, FileRead::ok) << read.detail;
  EXPECT_EQ(text, "from the writer\n");
}

TEST(FileRead, APipeThatNeverEndsStopsAtTheBound) {
  std::signal(SIGPIPE, SIG_IGN);
  int fds[2];
  ASSERT_EQ(pipe(fds), 0);
  std::thread writer([&] {
    std::string block(4096, 'y');
    while (write(fds[1], block.data(), block.size()) > 0) {
    }
  });
  std::string text;
  FileRead r = read_bounded_file("/proc/self/fd/" + std::to_string(fds[0]), 1 << 20, text, Pipes::read);
  close(fds[0]);  // the writer's next write fails (EPIPE; SIGPIPE is ignored below) and it ends
  writer.join();
  close(fds[1]);
  EXPECT_EQ(r.status, FileRead::too_large);
  EXPECT_GT(text.size(), std::size_t{1} << 20);
}

TEST(NumberText, ShowsANumberAsPrintfsShortestG) {
  EXPECT_EQ(eamos::diag::number_text(5), "5");
  EXPECT_EQ(eamos::diag::number_text(0.25), "0.25");
  EXPECT_EQ(eamos::diag::number_text(1e6), "1e+06");
  EXPECT_EQ(eamos::diag::number_text(-2.5), "-2.5");
}
