// `exotwin merge PART_DIR... --out DIR`: joins the folders of `exotwin sweep --shard K/N` runs (all N
// shards of one sweep) into the aggregate an unsharded run writes: DIR/sweep.csv, summary.json,
// sweep.json, plots/. Exit 0, or 2 if the parts do not form one complete sweep.
#include <CLI/CLI.hpp>

#include <cstdio>

#include "app/commands.h"
#include "runner/sweep_table.h"

namespace exotwin {
namespace {

CommandRunner RegisterMerge(CLI::App& app) {
  struct Opts {
    std::vector<std::string> parts;
    std::string out;
  };
  auto o = std::make_shared<Opts>();
  CLI::App* sub = app.add_subcommand("merge", "Join the shards of a sweep into one aggregate");
  sub->add_option("parts", o->parts, "shard folders (each written by exotwin sweep --shard K/N)")->required();
  sub->add_option("--out", o->out, "output folder")->required();
  return [sub, o]() -> int {
    if (!*sub) return -1;
    SweepManifest m;
    std::vector<SweepRow> rows;
    MergeSweepParts(o->parts, &m, &rows);
    WriteSweepAggregate(o->out, m, rows);
    std::printf("merge: %zu rows from %zu parts -> %s/sweep.csv, summary.json, plots/\n", rows.size(),
                o->parts.size(), o->out.c_str());
    return 0;
  };
}

const CommandRegistration kMerge(RegisterMerge);

}  // namespace
}  // namespace exotwin
