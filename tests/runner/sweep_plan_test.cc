// Sweep planning (scenarios/sweep_plan.h) and the aggregate tables (scenarios/sweep_table.h).
#include "tests/temp_dir.h"
#include "runner/sweep_plan.h"

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <set>

#include "core/error.h"
#include "runner/sweep_plots.h"
#include "runner/sweep_table.h"
#include "sim/subjects.h"

namespace exotwin {
namespace {

// The runner draws DrawSubject(random_seed, 0); SubjectSeed must make that subject i of the sweep.
TEST(SweepPlan, SubjectSeedGivesPopulationDrawIndex) {
  for (uint64_t seed : {1ull, 42ull, 0xdeadbeefull})
    for (int i : {0, 1, 7, 123}) {
      const Subject a = DrawSubject(SubjectSeed(seed, i), 0), b = DrawSubject(seed, i);
      EXPECT_EQ(a.weight, b.weight);
      EXPECT_EQ(a.L1, b.L1);
      EXPECT_EQ(a.human.J1, b.human.J1);
      EXPECT_EQ(a.exo.Y2, b.exo.Y2);
    }
  EXPECT_NE(DrawSubject(SubjectSeed(1, 1), 0).weight, DrawSubject(SubjectSeed(1, 2), 0).weight);
}

TEST(SweepPlan, WithPopulationSubjectReplacesPreset) {
  Scenario s;
  s.subject.preset = "S1";
  s.subject.passive = PassiveModel::kNone;
  const Scenario t = WithPopulationSubject(s, 5, 3);
  EXPECT_TRUE(t.subject.preset.empty());
  EXPECT_EQ(*t.subject.random_seed, SubjectSeed(5, 3));
  EXPECT_EQ(t.subject.passive, PassiveModel::kNone);
}

TEST(SweepPlan, ShardsPartitionTheSubjects) {
  EXPECT_EQ(ParseShard("2/5").k, 2);
  EXPECT_EQ(ParseShard("2/5").n, 5);
  for (const char* bad : {"5/5", "-1/3", "1/0", "a/b", "1", "1/", "/2", "1/2/3", " 1/2"})
    EXPECT_THROW(ParseShard(bad), InputError) << bad;
  std::multiset<std::pair<size_t, int>> all;
  for (int k = 0; k < 3; ++k)
    for (const SweepJob& j : PlanSweep(2, 10, {k, 3})) {
      EXPECT_EQ(j.subject % 3, k);
      all.insert({j.scenario, j.subject});
    }
  std::multiset<std::pair<size_t, int>> whole;
  for (const SweepJob& j : PlanSweep(2, 10, {})) whole.insert({j.scenario, j.subject});
  EXPECT_EQ(all, whole);
  EXPECT_EQ(whole.size(), 20u);
}

SweepRow Row(const std::string& sc, int i, double v) {
  SweepRow r;
  r.scenario = sc;
  r.subject = i;
  r.subject_seed = SubjectSeed(1, i);
  r.status = "ok";
  r.values = {{"m", v}, {"third", 1.0 / 3.0}};
  return r;
}

TEST(SweepTable, CsvRoundTripsBitForBit) {
  std::vector<SweepRow> rows = {Row("a,b", 0, 0.1 + 0.2), Row("c", 1, -1e-300), Row("c", 2, std::nan(""))};
  rows[1].values.erase("third");  // absent -> empty cell
  const std::string csv = SweepCsv(rows);
  const auto back = ParseSweepCsv(csv, "x.csv");
  ASSERT_EQ(back.size(), 3u);
  EXPECT_EQ(back[0].scenario, "a,b");
  EXPECT_EQ(back[0].values.at("m"), 0.1 + 0.2);
  EXPECT_EQ(back[1].values.count("third"), 0u);
  EXPECT_TRUE(std::isnan(back[2].values.at("m")));
  EXPECT_EQ(SweepCsv(back), csv);
  EXPECT_THROW(ParseSweepCsv("scenario,subject,subject_seed,status,checks_failed,m\nc,1,2,ok,0,zz\n", "y.csv"),
               InputError);
  EXPECT_THROW(ParseSweepCsv("a,b\n", "z.csv"), InputError);
}

// A sweep table goes through the CSV reader of every other CSV (formats/csv_table.h): a byte-order
// mark, CRLF, quotes and comments read as in a measured-data file; errors name file and line.
TEST(SweepTable, ReadByTheSharedCsvReader) {
  const auto rows = ParseSweepCsv(
      "\xEF\xBB\xBF# edited in a spreadsheet\r\n"
      "\"scenario\",subject,subject_seed,status,checks_failed,\"m, deg\"\r\n"
      "\"say \"\"a\"\"\",3,7,ok,0,\"1.5\"\r\n"
      "b,4,8,ok,1,\r\n",
      "s.csv");
  ASSERT_EQ(rows.size(), 2u);
  EXPECT_EQ(rows[0].scenario, "say \"a\"");
  EXPECT_EQ(rows[0].values.at("m, deg"), 1.5);
  EXPECT_EQ(rows[1].values.count("m, deg"), 0u);  // empty cell: no value
  EXPECT_EQ(rows[1].checks_failed, 1);
  try {
    ParseSweepCsv("scenario,subject,subject_seed,status,checks_failed,m\nc,1,2,ok,0,1,2\n", "w.csv");
    FAIL() << "a row with a field too many must be rejected";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("w.csv:2: expected 6 fields"), std::string::npos) << e.what();
  }
}

TEST(SweepTable, SummaryStatistics) {
  SweepManifest m;
  m.scenarios = {"s"};
  m.subjects = 5;
  std::vector<SweepRow> rows;
  for (int i = 0; i < 5; ++i) rows.push_back(Row("s", i, i + 1.0));  // 1..5
  rows.push_back(Row("s", 5, 100.0));
  rows.back().status = "diverged";  // not counted in the statistics
  const auto j = nlohmann::json::parse(SweepSummaryJson(m, rows));
  const auto& st = j["scenarios"]["s"]["metrics"]["m"];
  EXPECT_EQ(st["n"], 5);
  EXPECT_DOUBLE_EQ(st["mean"].get<double>(), 3.0);
  EXPECT_DOUBLE_EQ(st["sd"].get<double>(), std::sqrt(2.5));
  EXPECT_DOUBLE_EQ(st["p5"].get<double>(), 1.2);
  EXPECT_DOUBLE_EQ(st["p95"].get<double>(), 4.8);
  EXPECT_EQ(j["scenarios"]["s"]["status"]["diverged"], 1);
}

TEST(SweepTable, MergeRejectsMissingAndDuplicateShards) {
  const testing::ScopedTempDir tmp("sweep_merge");
  const std::filesystem::path base = tmp.path();
  SweepManifest m;
  m.scenarios = {"s"};
  m.files = {"s.yaml"};
  m.subjects = 4;
  for (int k = 0; k < 2; ++k) {
    m.shard = Shard{k, 2};
    std::vector<SweepRow> rows;
    for (int i = k; i < 4; i += 2) rows.push_back(Row("s", i, i));
    WriteSweepAggregate((base / ("p" + std::to_string(k))).string(), m, rows);
  }
  SweepManifest out;
  std::vector<SweepRow> rows;
  MergeSweepParts({(base / "p1").string(), (base / "p0").string()}, &out, &rows);
  ASSERT_EQ(rows.size(), 4u);
  for (int i = 0; i < 4; ++i) EXPECT_EQ(rows[i].subject, i);
  EXPECT_FALSE(out.shard.has_value());
  EXPECT_THROW(MergeSweepParts({(base / "p0").string()}, &out, &rows), InputError);
  EXPECT_THROW(MergeSweepParts({(base / "p0").string(), (base / "p0").string()}, &out, &rows), InputError);
  EXPECT_THROW(MergeSweepParts({(base / "nope").string()}, &out, &rows), InputError);
}

TEST(SweepPlots, HistogramSvgIsWellFormed) {
  const Histogram h = MakeHistogram("x", {1, 2, 2, 3, std::nan("")}, 4);
  EXPECT_EQ(h.n, 4u);
  int total = 0;
  for (int c : h.counts) total += c;
  EXPECT_EQ(total, 4);
  const std::string svg = HistogramGridSvg("t <&>", {h, MakeHistogram("empty", {}, 4)});
  EXPECT_EQ(svg.rfind("<?xml", 0), 0u);
  EXPECT_NE(svg.find("</svg>"), std::string::npos);
  EXPECT_NE(svg.find("t &lt;&amp;&gt;"), std::string::npos);
  EXPECT_NE(svg.find("no data"), std::string::npos);
  EXPECT_EQ(PlotFileName("a/b c"), "a_b_c.svg");
}

}  // namespace
}  // namespace exotwin
