// TemporaryDirectory: a fresh, unique directory under the system temp
// directory ($TMPDIR honoured), files written into it, everything removed on
// destruction, bad prefixes refused with a message.
#include "util/temporary_directory.h"

#include <gtest/gtest.h>

#include <cstdlib>
#include <fstream>
#include <iterator>
#include <string>

#include "util/expect_message.h"

namespace diffpd::testing {
namespace {

namespace fs = std::filesystem;

std::string ReadText(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  return std::string(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
}

TEST(TemporaryDirectoryTest, IsAFreshUniqueDirectoryUnderTheSystemTempDirectory) {
  const TemporaryDirectory a("diffpd-util"), b("diffpd-util");
  EXPECT_NE(a.path(), b.path());
  for (const TemporaryDirectory* d : {&a, &b}) {
    EXPECT_TRUE(fs::is_directory(d->path()));
    EXPECT_TRUE(fs::is_empty(d->path()));
    EXPECT_TRUE(d->path().is_absolute());
    EXPECT_EQ(fs::canonical(d->path().parent_path()), fs::canonical(fs::temp_directory_path()));
    EXPECT_EQ(d->path().filename().string().rfind("diffpd-util-", 0), 0u) << d->path();
  }
}

TEST(TemporaryDirectoryTest, WritesFilesAndRemovesEverythingOnDestruction) {
  fs::path kept;
  {
    const TemporaryDirectory dir("diffpd-util");
    kept = dir.path();
    const std::string path = dir.WriteFile("a.txt", "line 1\nline 2\n");
    EXPECT_EQ(path, (dir.path() / "a.txt").string());
    EXPECT_EQ(ReadText(path), "line 1\nline 2\n");
    EXPECT_EQ(ReadText(dir.WriteFile("a.txt", "replaced")), "replaced");
    EXPECT_EQ(dir.File("b.csv"), (dir.path() / "b.csv").string());
    EXPECT_FALSE(fs::exists(dir.File("b.csv")));  // File() creates nothing
    fs::create_directories(dir.path() / "sub" / "deeper");
    std::ofstream(dir.path() / "sub" / "deeper" / "c.bin") << "x";
  }
  EXPECT_FALSE(fs::exists(kept));
}

// The system temp directory is std::filesystem::temp_directory_path():
// $TMPDIR when set, so a run can be pointed elsewhere as a whole.
TEST(TemporaryDirectoryTest, HonoursTmpdir) {
  const TemporaryDirectory outer("diffpd-util");
  const char* saved = std::getenv("TMPDIR");
  const std::string previous = saved ? saved : "";
  setenv("TMPDIR", outer.path().c_str(), 1);
  fs::path inner_path;
  {
    const TemporaryDirectory inner("diffpd-util-inner");
    inner_path = inner.path();
  }
  if (saved) {
    setenv("TMPDIR", previous.c_str(), 1);
  } else {
    unsetenv("TMPDIR");
  }
  EXPECT_EQ(inner_path.parent_path(), outer.path());
  EXPECT_TRUE(fs::is_empty(outer.path()));
}

TEST(TemporaryDirectoryTest, RefusesBadPrefixesAndUnwritableFiles) {
  EXPECT_THROW_MESSAGE(TemporaryDirectory(""), std::invalid_argument,
                       "TemporaryDirectory: prefix '' must be non-empty without '/'");
  EXPECT_THROW_MESSAGE(TemporaryDirectory("a/b"), std::invalid_argument,
                       "TemporaryDirectory: prefix 'a/b' must be non-empty without '/'");
  const TemporaryDirectory dir("diffpd-util");
  const std::string blocked = dir.File("no-such-dir/a.txt");
  EXPECT_THROW_MESSAGE(dir.WriteFile("no-such-dir/a.txt", "x"), std::runtime_error,
                       "TemporaryDirectory: cannot write '" + blocked + "'");
}

}  // namespace
}  // namespace diffpd::testing
