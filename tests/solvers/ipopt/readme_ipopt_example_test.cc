// Runs the README's Ipopt example program (readme_ipopt_example.cc) and
// checks its answer against ballistics: 20 cm in 0.2 s needs v_x = 1 m/s,
// and 10 cm of height after 0.1 s needs v_z >= (0.1 + g 0.1^2 / 2) / 0.1.
#include <gtest/gtest.h>

#include <array>
#include <cstdio>
#include <string>

#include "util/readme_block.h"

namespace diffpd {
namespace {

TEST(ReadmeIpoptExampleTest, ThrowsTheCubeToTheTargetOverTheConstraint) {
  FILE* pipe = popen(DIFFPD_README_IPOPT_EXAMPLE " 2>&1", "r");
  ASSERT_NE(pipe, nullptr);
  std::string output;
  std::array<char, 512> buffer;
  while (std::fgets(buffer.data(), buffer.size(), pipe)) output += buffer.data();
  ASSERT_EQ(pclose(pipe), 0) << output;
  const size_t at = output.rfind("v0 = (");
  ASSERT_NE(at, std::string::npos) << output;
  double vx = 0, vy = 0, vz = 0;
  ASSERT_EQ(std::sscanf(output.c_str() + at, "v0 = (%lf, %lf, %lf)", &vx, &vy, &vz), 3) << output;
  // No horizontal force acts: the centre of mass moves at v_x exactly.
  EXPECT_NEAR(vx, 1.0, 1e-3) << output;
  EXPECT_NEAR(vy, 0.0, 1e-3) << output;
  // Implicit Euler rises a little less than the exact parabola.
  EXPECT_GE(vz, (0.1 + 9.81 * 0.01 / 2) / 0.1) << output;
  EXPECT_NE(output.find("Solve_Succeeded"), std::string::npos) << output;
}

// The README's Ipopt code block (after its marker) is a contiguous excerpt
// of the program compiled here, so the two cannot drift apart.
TEST(ReadmeIpoptExampleTest, ReadmeShowsAnExcerptOfTheExampleProgramVerbatim) {
  const std::string readme = testing::ReadTextFile(std::string(DIFFPD_SOURCE_DIR) + "/README.md");
  const std::string program =
      testing::ReadTextFile(std::string(DIFFPD_SOURCE_DIR) + "/tests/solvers/ipopt/readme_ipopt_example.cc");
  ASSERT_FALSE(program.empty());
  const std::string block = testing::CodeBlockAfter(readme, "<!-- The Ipopt example");
  EXPECT_GT(block.size(), 200u) << "README.md has no Ipopt example block, or it is nearly empty";
  EXPECT_NE(program.find(block), std::string::npos)
      << "README.md's Ipopt block must be a verbatim excerpt of tests/solvers/ipopt/readme_ipopt_example.cc:\n"
      << block;
}

}  // namespace
}  // namespace diffpd
