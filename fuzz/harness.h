// The contract every fuzz target checks, shared with the corpus-replay tests (tests/formats,
// tests/runner, ...), so that the smoke run in the normal test suite checks exactly what the fuzzers do:
// any input either parses or throws exotwin::InputError; what parses goes on through what the command
// would write from it, and that output must be valid text (core/file_text.h) and read back. Anything
// else (another exception, a crash, a sanitizer report) is a bug.
#pragma once
#include <cmath>
#include <stdexcept>
#include <string>
#include <vector>

#include "core/error.h"
#include "core/file_text.h"
#include "formats/bag_table.h"
#include "formats/column_map.h"
#include "formats/csv_table.h"
#include "formats/mcap_reader.h"
#include "formats/measured_data.h"
#include "formats/model_file.h"
#include "formats/opensim_kinematics.h"
#include "formats/opensim_storage.h"

namespace exotwin::fuzz {

// Output the twin wrote: must be valid text (a bug otherwise: bad input reached a writer).
inline void ExpectValidOutput(const std::string& text, const std::string& what) {
  if (const auto f = FindTextFault(text)) throw std::logic_error(what + ": written text not valid: " + f->Where());
}

// The measured data as `convert` writes it (WriteCsv of TableAsRecorded, comments from the inputs; a
// kinematics-only record its columns that hold samples), read back: the same number of rows.
inline void WriteMeasuredBack(const MeasuredData& d, const std::vector<std::string>& comments, const std::string& path) {
  const CsvTable table = TableAsRecorded(d);
  std::vector<std::string> names;
  std::vector<const std::vector<double>*> cols;
  for (size_t i = 0; i < table.columns.size(); ++i)
    if (table.columns[i].size() == table.rows()) names.push_back(table.names[i]), cols.push_back(&table.columns[i]);
  WriteCsv(path, names, cols, comments);
  ExpectValidOutput(ReadTextFile(path, "", "the CSV just written"), path);
  if (ReadCsv(path).rows() != table.rows()) throw std::logic_error(path + ": written CSV reads back another row count");
}

// Measured-data CSV file: parsed and validated (at least 2 rows, so the fuzzer reaches the
// validation quickly) and written back into the folder `scratch`; when it has the 20 rows the CLI
// asks for, the kinematics are derived as `predict` does (filtering, resampling of non-uniform
// sampling). Returns true if it parsed.
inline bool MeasuredCsvFile(const std::string& path, const std::string& scratch) {
  try {
    const MeasuredData d = ReadMeasuredCsv(path, 2);
    WriteMeasuredBack(d, {"source: " + path}, scratch + "/back.csv");
    if (d.size() >= 20) {
      const Kinematics k = DeriveKinematics(d);
      // A derivation that "succeeds" with NaN or inf is a silent wrong result: a bug, not bad input.
      for (int j = 0; j < 2; ++j)
        for (const auto* v : {&k.q[j], &k.qd[j], &k.qdd[j]})
          for (double x : *v)
            if (!std::isfinite(x)) throw std::logic_error("DeriveKinematics: non-finite result");
    }
    return true;
  } catch (const InputError&) {
    return false;
  }
}

// MODEL.yaml text. A model that parses must also survive a round trip through ModelToYaml (what
// diagnose writes as extended.yaml must be loadable by every command).
inline bool ModelYamlText(const std::string& text) {
  LegParams p;
  try {
    p = ParseModelYaml(text, "fuzz.yaml");
  } catch (const InputError&) {
    return false;
  }
  const std::string written = ModelToYaml(p);
  ExpectValidOutput(written, "ModelToYaml");
  ParseModelYaml(written, "roundtrip.yaml");  // must not throw at all
  return true;
}

// The separator of a column-map input: the map's YAML, then (optionally) the foreign CSV it converts.
inline constexpr const char* kCsvPart = "\n%%csv%%\n";

// `convert --map`: the column map (and the foreign CSV after kCsvPart; else a fixed two-joint CSV)
// read from files in `dir`, applied, and written as `convert` writes it (the report's lines as
// comments). Returns true if the map was applied.
inline bool ColumnMapText(const std::string& input, const std::string& dir) {
  const size_t cut = input.find(kCsvPart);
  const std::string map_text = input.substr(0, cut);
  const std::string csv_text = cut == std::string::npos
                                   ? "time,a,b,c,d\n0,0.1,0.2,1,2\n0.01,0.11,0.21,1.1,2.1\n0.02,0.12,0.22,1.2,2.2\n"
                                   : input.substr(cut + std::string(kCsvPart).size());
  const std::string map = dir + "/map.yaml", csv = dir + "/in.csv";
  WriteFileAtomic(map, map_text);
  WriteFileAtomic(csv, csv_text);
  try {
    MapReport report;
    const MeasuredData d = ReadMeasured(csv, map, 2, &report);
    std::vector<std::string> comments = {"source: " + csv, "map: " + map};
    for (const std::string& m : report.mapped) comments.push_back("  " + m);
    ExpectValidOutput(report.Summary(), "MapReport::Summary");
    WriteMeasuredBack(d, comments, dir + "/out.csv");
    return true;
  } catch (const InputError&) {
    return false;
  }
}

// An OpenSim storage (.sto / .mot) text: parsed, written back as a storage file (its labels and
// values) and read again (the same columns), and its leg's kinematics (either side present) as
// `predict --measured FILE.mot` takes them, written as a measured-data CSV. Returns true if it parsed.
inline bool StorageText(const std::string& text, const std::string& dir) {
  StorageTable t;
  try {
    t = ParseStorage(text, "fuzz.sto");
  } catch (const InputError&) {
    return false;
  }
  std::vector<const std::vector<double>*> cols;
  for (const auto& c : t.columns) cols.push_back(&c);
  bool written = false;
  try {
    WriteStorage(dir + "/back.sto", "fuzz", t.names, cols, t.in_degrees == 1, {"notes"});
    written = true;
  } catch (const InputError&) {  // e.g. no strictly increasing `time`: a table the writer refuses
  }
  if (written) {
    const std::string back = ReadTextFile(dir + "/back.sto", "", "the storage file just written");
    ExpectValidOutput(back, "WriteStorage");
    if (ParseStorage(back, "back.sto").names != t.names) throw std::logic_error("WriteStorage: labels do not read back");
  }
  for (const char* side : {"r", "l"}) {
    try {
      const MeasuredData d = KinematicsFromStorage(t, CoordinatesOfSide(side, "fuzz"), 2);
      WriteMeasuredBack(d, {"source: fuzz.sto"}, dir + "/kin.csv");
    } catch (const InputError&) {
    }
  }
  return true;
}

// The column map the bag target applies: the topics of its seeds (fuzz/corpus/fuzz_mcap, written by
// tests/mcap_client/write_bag.mjs fuzz-seeds): a JointState by names, another topic interpolated.
inline constexpr char kBagMap[] =
    "columns:\n"
    "  t:        {from: /exo/joint_states.header.stamp}\n"
    "  q_hip:    {from: \"/exo/joint_states.position[hip_flexion_joint]\"}\n"
    "  q_knee:   {from: \"/exo/joint_states.position[knee_joint]\"}\n"
    "  tau_hip:  {from: \"/exo/joint_states.effort[1]\", sign: -1}\n"
    "  tau_knee: {from: \"/exo/joint_states.effort[knee_joint]\", sign: -1}\n"
    "  cmd_knee: {from: \"/exo/command.data[1]\"}\n";

// An MCAP file's bytes (via a scratch file in `dir`): parsed (ParseMcap through ReadMcapRecord), every
// message of every channel decoded by its channel (CDR by its ros2msg schema, JSON), then read through
// kBagMap as `convert --map` reads it, and written back. The messages of the InputErrors must be valid
// text (the bag's bytes are quoted only through ShownText). Returns true if the file parsed.
inline bool McapBytes(const std::string& input, const std::string& dir) {
  const std::string bag = dir + "/in.mcap", map = dir + "/map.yaml";
  WriteFileAtomic(bag, input);
  const auto refused = [](const InputError& e) { ExpectValidOutput(e.what(), "InputError message"); };
  McapRecord r;
  try {
    r = ReadMcapRecord(bag);
  } catch (const InputError& e) {
    refused(e);
    return false;
  }
  for (size_t c = 0; c < r.channels.size(); ++c) {
    try {
      const ChannelDecoder decode(r.channels[c], bag, "fuzz");
      for (const McapMessage& m : r.messages) {
        if (m.channel != c) continue;
        try {
          decode(m, m.where);
        } catch (const InputError& e) {
          refused(e);
        }
      }
    } catch (const InputError& e) {
      refused(e);
    }
  }
  WriteFileAtomic(map, kBagMap);
  try {
    MapReport report;
    const MeasuredData d = ReadMeasured(bag, map, 2, &report);
    ExpectValidOutput(report.Summary(), "MapReport::Summary");
    WriteMeasuredBack(d, {"source: " + bag, "map: " + map}, dir + "/out.csv");
  } catch (const InputError& e) {
    refused(e);
  }
  return true;
}

}  // namespace exotwin::fuzz
