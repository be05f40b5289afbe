// The commands and readers: exotwin._command runs a sub-command of the exotwin program in this
// process (app/'s registry: the same options, checks, files and messages); the readers return what the
// project's own readers read (formats/), columns as NumPy arrays that own their std::vector.
#include <CLI/CLI.hpp>

#include <utility>

#include "app/commands.h"
#include "core/data_dir.h"
#include "core/error.h"
#include "formats/column_map.h"
#include "formats/csv_table.h"
#include "formats/measured_data.h"
#include "formats/model_file.h"
#include "formats/opensim_storage.h"
#include "python/module.h"

namespace exotwin::python {
namespace {

// A column as a 1-D float64 array that takes the vector (no copy).
py::array ColumnArray(std::vector<double>&& column) { return RowsArray(std::move(column), 1).attr("reshape")(-1); }

py::dict ColumnsDict(const std::vector<std::string>& names, std::vector<std::vector<double>>& columns) {
  py::dict d;
  for (size_t i = 0; i < names.size(); ++i) d[py::str(names[i])] = ColumnArray(std::move(columns[i]));
  return d;
}

// `exotwin ARGS...` in this process, the interpreter's lock released; returns its exit code (0, or 1
// for a failed check). A usage error (CLI11) is an InputError with CLI11's text; the commands' own
// InputError / SimulationError propagate.
int Command(const std::vector<std::string>& args) {
  py::gil_scoped_release release;
  CLI::App app{"exotwin"};
  app.require_subcommand(1);
  std::vector<CommandRunner> runners;
  for (CommandFactory factory : CommandFactories()) runners.push_back(factory(app));
  std::vector<std::string> reversed(args.rbegin(), args.rend());  // CLI11 parses from the back
  try {
    app.parse(reversed);
  } catch (const CLI::ParseError& e) {
    std::string line = "exotwin";
    for (const std::string& a : args) line += " " + a;
    throw InputError(line + ": " + e.what());
  }
  for (CommandRunner& run : runners)
    if (const int rc = run(); rc >= 0) return rc;
  throw InputError("exotwin: no command ran");
}

py::dict ReadCsvColumns(const std::string& path) {
  CsvTable t;
  {
    py::gil_scoped_release release;
    t = ReadCsv(path);
  }
  return ColumnsDict(t.names, t.columns);
}

// A measured-data record as ReadMeasured reads it (with a column map when `map` is not empty): the
// table's columns in file order (a one-joint record: its knee, the hip columns not added).
py::dict ReadMeasuredColumns(const std::string& path, const std::string& map) {
  MeasuredData data;
  MapReport report;
  {
    py::gil_scoped_release release;
    data = ReadMeasured(path, map, 20, &report);
  }
  std::vector<std::string> names = data.table.names;
  std::vector<std::vector<double>> columns = std::move(data.table.columns);
  if (data.one_joint)  // the embedding's hip columns (EmbedOneJoint) are not the file's
    for (size_t i = names.size(); i-- > 0;)
      if (names[i] == "q_hip" || names[i] == "tau_hip") names.erase(names.begin() + i), columns.erase(columns.begin() + i);
  return ColumnsDict(names, columns);
}

py::dict ReadStorageColumns(const std::string& path) {
  StorageTable t;
  {
    py::gil_scoped_release release;
    t = ReadStorage(path);
  }
  py::dict d = ColumnsDict(t.names, t.columns);
  return d;
}

py::dict LumpedDict(const LumpedParams& p) {
  py::dict d;
  d["J1"] = p.J1, d["J2"] = p.J2, d["X1"] = p.X1, d["X2"] = p.X2, d["Y1"] = p.Y1, d["Y2"] = p.Y2;
  if (p.m1 > 0) d["m1"] = p.m1;
  if (p.m2 > 0) d["m2"] = p.m2;
  return d;
}

// A model file (ReadModelFile) as a dict of its fields, and its text as ModelToYaml writes it.
py::dict ReadModel(const std::string& path) {
  const LegParams p = ReadModelFile(path);
  py::dict d;
  d["L1"] = p.L1;
  d["g"] = p.g;
  d["exo"] = LumpedDict(p.exo);
  d["human"] = p.human ? py::object(LumpedDict(*p.human)) : py::object(py::none());
  d["passive"] = PassiveModelName(p.passive);
  py::list effects;
  for (const Effect& e : p.effects) {
    py::dict x;
    x["name"] = e.name;
    x["joint"] = e.joint;
    x["value"] = e.value;
    x["unit"] = e.unit;
    for (const auto& kv : e.fields) x[py::str(kv.first)] = kv.second;
    if (!e.axis.empty()) x["axis"] = e.axis;
    if (!e.expr.empty()) x["expr"] = e.expr;  // a term's (DESIGN.md "Terms beyond the table")
    if (!e.stage.empty()) x["stage"] = e.stage;
    effects.append(x);
  }
  d["effects"] = effects;
  if (p.one_joint) {
    py::dict o;
    o["I"] = p.one_joint->device.I;
    o["mgl"] = p.one_joint->device.mgl;
    o["R"] = p.one_joint->R;
    o["C"] = p.one_joint->C;
    if (p.one_joint->human) o["human"] = py::dict(py::arg("I") = p.one_joint->human->I, py::arg("mgl") = p.one_joint->human->mgl);
    d["one_joint"] = o;
  }
  d["yaml"] = ModelToYaml(p);
  return d;
}

}  // namespace

void BindCommands(py::module_& m) {
  m.def("_command", &Command, py::arg("args"), "runs `exotwin ARGS...` in this process; returns its exit code");
  m.def("_read_csv", &ReadCsvColumns, py::arg("path"));
  m.def("_read_measured", &ReadMeasuredColumns, py::arg("path"), py::arg("map"));
  m.def("_read_sto", &ReadStorageColumns, py::arg("path"));
  m.def("_read_model", &ReadModel, py::arg("path"));
  m.def("data_dir", &DataDir, "the data folder (mjcf/, data/, scenarios/, examples/; core/data_dir.h's rule, the "
        "package's P/share/exotwin unless EXOTWIN_DATA_DIR says otherwise)");
}

}  // namespace exotwin::python
