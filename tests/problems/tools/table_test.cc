// `diffpd table` on the small cantilever and plant rows: what it measures and
// derives (speed-up, normalised loss), the JSON round trip, resuming,
// the time budget, option errors and the reports.
#include "tools/table.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <sstream>

#include "diffpd/error.h"
#include "tools/table_report.h"
#include "tools/tradeoff.h"

namespace diffpd::problems {
namespace {

TableOptions SmallOptions() {
  TableOptions o;
  o.command = "diffpd table --small --rows cantilever,plant";
  o.rows = {"cantilever", "plant"};
  o.methods = {Method::kPdLbfgs, Method::kNewtonCholesky};
  o.threads = 1;
  o.size = RowSize::kSmall;
  o.evaluations = 2;
  o.newton_evaluations = 1;
  return o;
}

// One run shared by the tests (a few seconds).
const TableResult& SmallRun() {
  static const TableResult result = RunTable(SmallOptions(), nullptr, {}, nullptr);
  return result;
}

int CountLines(const std::string& text, const std::string& what) {
  int n = 0;
  for (size_t at = text.find(what); at != std::string::npos; at = text.find(what, at + 1)) ++n;
  return n;
}

TEST(TableTest, EveryRowAndMethodIsMeasuredWithItsEvaluationCount) {
  const TableResult& r = SmallRun();
  ASSERT_EQ(r.rows.size(), 2u);
  EXPECT_FALSE(r.budget_exhausted);
  for (const TableRowResult& row : r.rows) {
    EXPECT_TRUE(row.complete) << row.row;
    ASSERT_EQ(row.methods.size(), 2u);
    EXPECT_EQ(row.method("pd-lbfgs")->evaluations, 2);
    EXPECT_EQ(row.method("newton-cholesky")->evaluations, 1);
    for (const TableMethodResult& m : row.methods) {
      EXPECT_TRUE(m.failure.empty()) << m.failure;
      ASSERT_EQ(static_cast<int>(m.forward_samples.size()), m.evaluations);
      double sum = 0;
      for (double s : m.forward_samples) sum += s;
      EXPECT_NEAR(m.forward_s, sum / m.evaluations, 1e-12);
      EXPECT_GT(m.forward_s, 0);
      EXPECT_GT(m.backward_s, 0);
    }
  }
  EXPECT_EQ(r.rows[0].random_draws, 0);  // the cantilever is timing only
  EXPECT_EQ(r.rows[1].random_losses.size(), 16u);
}

TEST(TableTest, SpeedupIsNewtonTimeOverPdLbfgsTime) {
  for (const TableRowResult& row : SmallRun().rows) {
    const TableMethodResult* pd = row.method("pd-lbfgs");
    const TableMethodResult* newton = row.method("newton-cholesky");
    ASSERT_TRUE(row.speedup);
    EXPECT_DOUBLE_EQ(*row.speedup, (newton->forward_s + newton->backward_s) / (pd->forward_s + pd->backward_s));
  }
}

TEST(TableTest, PlantLossIsNormalisedByTheMeanRandomDrawLoss) {
  const TableRowResult& plant = SmallRun().rows[1];
  double mean = 0;
  for (double l : plant.random_losses) mean += l / 16;
  ASSERT_TRUE(plant.random_loss_mean);
  EXPECT_NEAR(*plant.random_loss_mean, mean, 1e-12 * std::abs(mean));
  ASSERT_TRUE(plant.baseline);
  EXPECT_EQ(*plant.baseline, 0.0);
  const TableMethodResult* pd = plant.method("pd-lbfgs");
  ASSERT_TRUE(pd->normalised_loss);
  EXPECT_DOUBLE_EQ(*pd->normalised_loss, pd->loss / mean);
  // The two methods solve the same rollout to the same tolerance.
  EXPECT_NEAR(plant.method("newton-cholesky")->loss, pd->loss, 1e-3 * std::abs(pd->loss));
  EXPECT_FALSE(SmallRun().rows[0].method("pd-lbfgs")->normalised_loss);  // timing row: no normalisation
}

TEST(TableTest, JsonRoundTripAndAResumeOfAFinishedRunMeasuresNothing) {
  const TableResult back = TableFromJson(TableToJson(SmallRun()));
  ASSERT_EQ(back.rows.size(), 2u);
  EXPECT_EQ(back.rows[1].random_losses, SmallRun().rows[1].random_losses);
  EXPECT_EQ(back.rows[1].methods[0].forward_s, SmallRun().rows[1].methods[0].forward_s);
  std::ostringstream progress;
  const TableResult resumed = RunTable(SmallOptions(), &back, {}, &progress);
  EXPECT_EQ(CountLines(progress.str(), "evaluation"), 0) << progress.str();
  EXPECT_EQ(CountLines(progress.str(), "random draw"), 0) << progress.str();
  EXPECT_EQ(resumed.rows[1].method("newton-cholesky")->forward_s,
            SmallRun().rows[1].method("newton-cholesky")->forward_s);
}

TEST(TableTest, AReportOnlyRunOfAPartialResultMeasuresNothingAndAddsNoRun) {
  TableResult partial = TableFromJson(TableToJson(SmallRun()));
  partial.rows[0].methods.pop_back();  // the cantilever's newton-cholesky
  partial.rows[0].complete = false;
  TableOptions o = SmallOptions();
  o.measure = false;
  o.threads = 2;  // a report takes the file's settings, whatever the options say
  o.evaluations = 5;
  std::ostringstream progress;
  const TableResult report = RunTable(o, &partial, {}, &progress);
  EXPECT_EQ(report.threads, 1);
  EXPECT_EQ(report.evaluations, 2);
  EXPECT_EQ(CountLines(progress.str(), "evaluation"), 0) << progress.str();
  EXPECT_TRUE(report.resumed_runs.empty());
  EXPECT_FALSE(report.rows[0].complete);
  EXPECT_EQ(report.rows[0].method("newton-cholesky"), nullptr);
  EXPECT_EQ(report.rows[1].method("pd-lbfgs")->forward_s, SmallRun().rows[1].method("pd-lbfgs")->forward_s);
}

TEST(TableTest, ResumeMeasuresOnlyTheUnfinishedMethod) {
  TableResult partial = TableFromJson(TableToJson(SmallRun()));
  partial.rows[0].methods.pop_back();  // the cantilever's newton-cholesky
  partial.rows[0].complete = false;
  int checkpoints = 0;
  std::ostringstream progress;
  const TableResult resumed = RunTable(
      SmallOptions(), &partial, [&](const TableResult&) { ++checkpoints; }, &progress);
  EXPECT_EQ(CountLines(progress.str(), "evaluation"), 1) << progress.str();
  EXPECT_EQ(CountLines(progress.str(), "cantilever newton-cholesky evaluation 1/1"), 1) << progress.str();
  EXPECT_TRUE(resumed.rows[0].complete);
  EXPECT_GE(checkpoints, 1);
}

TEST(TableTest, FewerDrawsLeaveTheRowIncompleteAndAResumeFinishesThem) {
  TableOptions o = SmallOptions();
  o.rows = {"plant", "cantilever"};
  o.methods = {Method::kPdLbfgs};
  o.random_draws = 3;
  const TableResult part = RunTable(o, nullptr, {}, nullptr);
  EXPECT_FALSE(part.budget_exhausted);
  EXPECT_EQ(part.rows[1].method("pd-lbfgs")->evaluations, 2);  // the next row runs all the same
  EXPECT_EQ(part.rows[0].random_losses.size(), 3u);
  EXPECT_FALSE(part.rows[0].complete);
  EXPECT_FALSE(part.rows[0].random_loss_mean);
  EXPECT_EQ(part.rows[0].method("pd-lbfgs")->evaluations, 2);  // the methods run all the same
  o.random_draws = 16;
  std::ostringstream progress;
  const TableResult whole = RunTable(o, &part, {}, &progress);
  EXPECT_EQ(whole.rows[0].random_losses.size(), 16u);
  EXPECT_TRUE(whole.rows[0].complete);
  EXPECT_EQ(CountLines(progress.str(), "random draw"), 13) << progress.str();
  EXPECT_EQ(CountLines(progress.str(), "evaluation"), 0) << progress.str();
  EXPECT_EQ(whole.rows[0].random_losses[1], part.rows[0].random_losses[1]);
  ASSERT_EQ(whole.resumed_runs.size(), 1u);
  EXPECT_EQ(whole.date, part.date);
}

TEST(TableTest, ASpentBudgetStopsBeforeTheFirstEvaluation) {
  TableOptions o = SmallOptions();
  o.budget_minutes = 1e-12;
  const TableResult r = RunTable(o, nullptr, {}, nullptr);
  EXPECT_TRUE(r.budget_exhausted);
  for (const TableRowResult& row : r.rows) {
    EXPECT_FALSE(row.complete) << row.row;
    for (const TableMethodResult& m : row.methods) EXPECT_EQ(m.evaluations, 0);
  }
}

TEST(TableTest, BadOptionsAndAMismatchedResumeAreRefused) {
  TableOptions o = SmallOptions();
  o.evaluations = 0;
  try {
    RunTable(o, nullptr, {}, nullptr);
    FAIL() << "expected InvalidInputError";
  } catch (const InvalidInputError& e) {
    EXPECT_STREQ(e.what(), "evaluations = 0 is invalid: must be >= 1");
  }
  TableResult other = SmallRun();
  other.threads = 4;
  try {
    RunTable(SmallOptions(), &other, {}, nullptr);
    FAIL() << "expected InvalidInputError";
  } catch (const InvalidInputError& e) {
    EXPECT_STREQ(e.what(), "resume: the file was measured with 4 threads, this run asks for 1");
  }
  try {
    TableFromJson(nlohmann::json::object({{"date", "x"}}));
    FAIL() << "expected InvalidInputError";
  } catch (const InvalidInputError& e) {
    EXPECT_STREQ(e.what(), "table JSON: the document has no field 'commit'");
  }
}

TEST(TableTest, RowsHaveTheOriginalsMassesUnlessLumpedOnesAreAskedForAndThenSaySo) {
  const TableResult& equal = SmallRun();
  EXPECT_EQ(equal.masses, "equal-nodes");
  TableOptions o = SmallOptions();
  o.rows = {"plant"};
  o.methods = {Method::kPdLbfgs};
  o.evaluations = 1;
  o.masses = MassLumping::kLumped;
  const TableResult lumped = RunTable(o, nullptr, {}, nullptr);
  EXPECT_EQ(lumped.masses, "lumped");
  EXPECT_EQ(TableFromJson(TableToJson(lumped)).masses, "lumped");
  const TableRowResult& plant = lumped.rows[0];
  const auto noted = [](const TableRowResult& row) {
    for (const std::string& note : row.notes)
      if (note.rfind("masses: lumped", 0) == 0) return true;
    return false;
  };
  EXPECT_TRUE(noted(plant));
  EXPECT_FALSE(noted(equal.rows[1]));
  // The masses change the plant's motion, so its loss at x_init.
  const double l_equal = equal.rows[1].method("pd-lbfgs")->loss;
  const double l_lumped = plant.method("pd-lbfgs")->loss;
  EXPECT_GT(std::abs(l_equal - l_lumped), 1e-3 * std::abs(l_equal)) << l_equal << " " << l_lumped;
  o.masses = MassLumping::kEqualNodes;
  try {
    RunTable(o, &lumped, {}, nullptr);
    FAIL() << "expected InvalidInputError";
  } catch (const InvalidInputError& e) {
    EXPECT_STREQ(e.what(), "resume: the file was measured with lumped masses, this run asks for equal-nodes");
  }
}

TEST(TableTest, TheCommandThatMeasuredTheResultIsStoredAndReported) {
  const TableResult& r = SmallRun();
  EXPECT_EQ(r.command, "diffpd table --small --rows cantilever,plant");
  const TableResult back = TableFromJson(TableToJson(r));
  EXPECT_EQ(back.command, r.command);
  // A resume keeps the first run's command and labels itself with its own.
  TableOptions o = SmallOptions();
  o.command = "diffpd table --resume";
  const TableResult resumed = RunTable(o, &back, {}, nullptr);
  EXPECT_EQ(resumed.command, r.command);
  ASSERT_EQ(resumed.resumed_runs.size(), 1u);
  EXPECT_NE(resumed.resumed_runs[0].find(": diffpd table --resume"), std::string::npos) << resumed.resumed_runs[0];
  std::FILE* text = std::tmpfile();
  PrintTable(r, text);
  std::rewind(text);
  std::string printed;
  for (int c; (c = std::fgetc(text)) != EOF;) printed += static_cast<char>(c);
  std::fclose(text);
  EXPECT_NE(printed.find("# command: diffpd table --small --rows cantilever,plant\n"), std::string::npos) << printed;
  const std::string md = TableMarkdown(r, "diffpd table --report --json x.json");
  EXPECT_NE(md.find("    diffpd table --small --rows cantilever,plant\n"), std::string::npos) << md;
  EXPECT_NE(md.find("Reported by:\n\n    diffpd table --report --json x.json"), std::string::npos) << md;
}

TEST(TableTest, ReportsCarryThePapersNumbersAndTheNotes) {
  const std::string md = TableMarkdown(SmallRun(), "diffpd table --small");
  EXPECT_NE(md.find("| 3 plant |"), std::string::npos) << md;
  EXPECT_NE(md.find("929.6"), std::string::npos);           // the paper's Newton-Cholesky forward seconds for the plant
  EXPECT_EQ(md.find("masses: lumped"), std::string::npos);  // the rows have the original's masses
  EXPECT_NE(md.find("diffpd table --small"), std::string::npos);
  EXPECT_EQ(TableFromJson(TableToJson(SmallRun())).optimizer, "lbfgsb");
  nlohmann::json old = TableToJson(SmallRun());
  old.erase("optimizer");  // a file from before the option: optimised with Ipopt
  old.erase("command");
  EXPECT_EQ(TableFromJson(old).optimizer, "ipopt");
  EXPECT_EQ(TableFromJson(old).command, "");
  if (GnuplotAvailable()) {
    const std::string png = (std::filesystem::temp_directory_path() / "diffpd_table_test.png").string();
    std::filesystem::remove(png);
    WriteTablePlot(SmallRun(), png);
    EXPECT_GT(std::filesystem::file_size(png), 1000u);
    std::filesystem::remove(png);
  }
}

}  // namespace
}  // namespace diffpd::problems
