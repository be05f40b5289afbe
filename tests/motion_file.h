// OpenSim motion files (.mot / .sto) written by the tests themselves, in each variant the format
// allows (formats/opensim_storage.h): no third-party motion file is copied into the project.
#pragma once
#include <cmath>
#include <cstdio>
#include <string>
#include <vector>

namespace exotwin::testing {

struct MotVariant {
  enum class Header {
    kVersion1,   // OpenSim's own: name, version=1, nRows, nColumns, inDegrees, endheader
    kToolLines,  // only the lines some tools write: name, nRows, nColumns, inDegrees, endheader
    kSimm,       // SIMM-era: name, datacolumns N, datarows N, range, inDegrees, endheader (no '=' counts)
    kNone,       // no header: the column names line first (the angle unit cannot be told)
  };
  Header header = Header::kVersion1;
  bool in_degrees = true;      // the unit of the angle columns
  bool state_unit = true;      // false: no inDegrees line
  char sep = '\t';             // '\t' or ' '
  bool trailing_sep = false;   // a separator at the end of every line
  bool crlf = false;           // CR LF line ends
  std::string side = "r";      // r | l
  int n_columns = -1;          // the header's nColumns; -1: the true count
};

// Columns time, pelvis_tilt, hip_flexion_<side>, hip_adduction_<side>, knee_angle_<side>,
// ankle_angle_<side>; hip and knee given in rad, written in the variant's unit ("%.17g").
inline std::string MotText(const std::vector<double>& t, const std::vector<double>& hip,
                           const std::vector<double>& knee, const MotVariant& v) {
  const std::string eol = v.crlf ? "\r\n" : "\n";
  const std::string s = v.side;
  const std::vector<std::string> names = {"time", "pelvis_tilt", "hip_flexion_" + s, "hip_adduction_" + s,
                                          "knee_angle_" + s, "ankle_angle_" + s};
  const int ncol = v.n_columns >= 0 ? v.n_columns : static_cast<int>(names.size());
  const std::string rows = std::to_string(t.size());
  std::string out;
  const std::string unit = v.state_unit ? std::string("inDegrees=") + (v.in_degrees ? "yes" : "no") + eol : "";
  switch (v.header) {
    case MotVariant::Header::kVersion1:
      out = "Coordinates" + eol + "version=1" + eol + "nRows=" + rows + eol + "nColumns=" + std::to_string(ncol) +
            eol + unit + eol + "Units are S.I. units (second, meters, Newtons, ...)" + eol +
            "If the header above contains a line with 'inDegrees', this indicates whether rotational values are "
            "in degrees (yes) or radians (no)." + eol + eol + "endheader" + eol;
      break;
    case MotVariant::Header::kToolLines:
      out = "walk.mot" + eol + "nRows=" + rows + eol + "nColumns=" + std::to_string(ncol) + eol + unit + "endheader" + eol;
      break;
    case MotVariant::Header::kSimm:
      out = "name walk.mot" + eol + "datacolumns " + std::to_string(ncol) + eol + "datarows " + rows + eol +
            "range " + std::to_string(t.front()) + " " + std::to_string(t.back()) + eol + unit + "endheader" + eol;
      break;
    case MotVariant::Header::kNone:
      break;
  }
  auto line = [&](const std::vector<std::string>& f) {
    for (size_t i = 0; i < f.size(); ++i) out += (i ? std::string(1, v.sep) : "") + f[i];
    if (v.trailing_sep) out += v.sep;
    out += eol;
  };
  line(names);
  const double k = v.in_degrees ? 180.0 / M_PI : 1.0;
  char b[40];
  auto num = [&](double x) {
    std::snprintf(b, sizeof b, "%.17g", x);
    return std::string(b);
  };
  for (size_t i = 0; i < t.size(); ++i)
    line({num(t[i]), num(2.0), num(hip[i] * k), num(-3.0), num(knee[i] * k), num(5.0)});
  return out;
}

}  // namespace exotwin::testing
