// Opening input files (diffpd/input_file.h): one message per failure, and
// the size readers bound their header counts with.
#include "diffpd/input_file.h"

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <limits>
#include <string>

#include "diffpd/error.h"
#include "util/expect_message.h"
#include "util/temporary_directory.h"

namespace diffpd {
namespace {

const std::filesystem::path& TestDirectory() {
  static const testing::TemporaryDirectory directory("diffpd-input-file");
  return directory.path();
}

TEST(InputFileTest, RefusesMissingFilesAndDirectoriesByName) {
  const std::string dir = TestDirectory().string();
  const std::string missing = (TestDirectory() / "missing.csv").string();
  const std::pair<std::string, std::string> cases[] = {
      {missing, "cannot open '" + missing + "'"},
      {dir, "cannot open '" + dir + "': it is a directory, not a file"},
      {"", "cannot open ''"},
  };
  for (const auto& [path, message] : cases) {
    EXPECT_THROW_MESSAGE(OpenInputFile(path), InvalidInputError, message);
  }
}

TEST(InputFileTest, OpensRegularFilesAndReportsTheirSize) {
  const std::string path = (TestDirectory() / "five.txt").string();
  std::ofstream(path) << "1234\n";
  std::ifstream in = OpenInputFile(path);
  std::string line;
  ASSERT_TRUE(std::getline(in, line));
  EXPECT_EQ(line, "1234");
  EXPECT_EQ(InputFileSize(path), 5u);
  EXPECT_EQ(InputFileSize((TestDirectory() / "missing.csv").string()), std::numeric_limits<std::uintmax_t>::max());
}

}  // namespace
}  // namespace diffpd
