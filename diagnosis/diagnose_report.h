// Human-readable diagnosis report: one self-contained HTML page with inline SVG plots.
#pragma once
#include <string>

#include "diagnosis/diagnose.h"

namespace exotwin {

// HTML text of the report for `d` (plots: measured vs twin before/after, residual against angle,
// velocity, acceleration and time, residual spectrum; tables of effects, candidates, scores).
std::string DiagnosisReportHtml(const Diagnosis& d, const std::string& params_path,
                                const std::string& measured_path);

}  // namespace exotwin
