// The run's ROS 2 bag: see run_bag.h.
#include "runner/run_bag.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <map>

#include "formats/mcap_format.h"

namespace exotwin {
namespace {

// The joints of a log's JointState topic: the columns of position, velocity and effort (nullptr: none;
// the measured log's velocity is the controller's estimate, handed to BagLog::Row) and the effort's sign.
struct JointColumns {
  const char *name, *position, *velocity, *effort;
  double effort_sign;
};
const JointColumns kMeasuredJoints[] = {{"hip", "q_hip", nullptr, "tau_hip", -1},
                                        {"knee", "q_knee", nullptr, "tau_knee", -1}};
const JointColumns kTruthJoints[] = {{"hip", "q_hip", "qd_hip", "tau_R_hip", 1},
                                     {"knee", "q_knee", "qd_knee", "tau_R_knee", 1},
                                     {"knee", "th", "thd", "tau_motor", 1}};  // HAL-3

// The Float64MultiArray topics: the columns named, or starting with a name that ends in '_'.
struct ArrayColumns {
  const char* topic;
  std::vector<std::string> names;
};
const std::vector<ArrayColumns> kMeasuredArrays = {
    {"/exo/command", {"cmd_"}},
    {"/exo/reference", {"ref_"}},
    {"/exo/emg", {"emg_"}},
    {"/exo/safety_state", {"state"}},
    {"/exo/assist", {"E_ext", "E_flex", "mu_hat", "D_hat", "K_hat"}}};
const std::vector<ArrayColumns> kTruthArrays = {
    {"/exo/truth/muscle_torque", {"tau_M_", "tau_muscle"}},
    {"/exo/truth/human", {"tau_interaction", "D_true", "K_true", "mu_contraction"}}};

bool Matches(const std::string& column, const std::string& name) {
  return name.back() == '_' ? column.rfind(name, 0) == 0 : column == name;
}

int IndexOf(const std::vector<std::string>& columns, const char* name) {
  if (!name) return -1;
  const auto it = std::find(columns.begin(), columns.end(), name);
  return it == columns.end() ? -1 : static_cast<int>(it - columns.begin());
}

std::string Join(const std::vector<std::string>& columns, const std::vector<int>& indexes) {
  std::string s;
  for (int i : indexes) s += (s.empty() ? "" : ",") + columns[static_cast<size_t>(i)];
  return s;
}

}  // namespace

RunBag::RunBag(const std::string& path, const Scenario& s, uint64_t seed) : writer_(path, mcap::McapWriter::Options{}) {
  joint_state_schema_ = writer_.AddSchema(cdr::kJointStateType, mcap::kSchemaEncodingRos2Msg, cdr::JointStateDefinition());
  array_schema_ =
      writer_.AddSchema(cdr::kFloat64MultiArrayType, mcap::kSchemaEncodingRos2Msg, cdr::Float64MultiArrayDefinition());
  writer_.AddMetadata("exotwin", {{"scenario", s.name},
                                  {"seed", std::to_string(seed)},
                                  {"scenario_file", s.source},
                                  {"trial_spacing_s", std::to_string(s.protocol.duration + 1.0)}});
}

uint16_t RunBag::Channel(const std::string& topic, bool joint_state) {
  for (const auto& [t, id] : channels_)
    if (t == topic) return id;
  const uint16_t id =
      writer_.AddChannel(joint_state ? joint_state_schema_ : array_schema_, topic, mcap::kMessageEncodingCdr);
  channels_.emplace_back(topic, id);
  return id;
}

std::unique_ptr<BagLog> RunBag::Open(BagLogKind kind, const std::vector<std::string>& columns, double epoch) {
  auto log = std::make_unique<BagLog>();
  log->bag_ = this;
  log->epoch_ = epoch;
  const bool measured = kind == BagLogKind::kMeasured;
  std::vector<bool> used(columns.size(), false);
  used[0] = true;  // t: the stamp
  auto take = [&](int i) {
    if (i >= 0) used[static_cast<size_t>(i)] = true;
    return i;
  };
  cdr::CdrWriter c;
  std::vector<std::string> names;
  for (const JointColumns& j : measured ? std::vector<JointColumns>(std::begin(kMeasuredJoints), std::end(kMeasuredJoints))
                                        : std::vector<JointColumns>(std::begin(kTruthJoints), std::end(kTruthJoints))) {
    const int q = IndexOf(columns, j.position);
    if (q < 0) continue;
    log->joints_.push_back({j.name, take(q), take(IndexOf(columns, j.velocity)), take(IndexOf(columns, j.effort)),
                            j.effort_sign});
    names.push_back(j.name);
  }
  if (!log->joints_.empty()) {
    log->joint_channel_ = Channel(measured ? "/exo/joint_states" : "/exo/truth/joint_states", true);
    const std::vector<double> zero(names.size(), 0.0);
    log->joint_layout_ = cdr::JointState(c, 0, "", names, zero.data(), zero.data(), zero.data(), names.size());
    log->joint_message_ = c.bytes();
  }
  auto add_array = [&](const std::string& topic, std::vector<int> indexes) {
    if (indexes.empty()) return;
    BagLog::Array array;
    array.channel = Channel(topic, false);
    const std::vector<double> zero(indexes.size(), 0.0);
    c.Reset();
    array.data_at = cdr::Float64MultiArray(c, Join(columns, indexes), zero.data(), zero.size());
    array.message = c.bytes();
    array.columns = std::move(indexes);
    log->arrays_.push_back(std::move(array));
  };
  for (const ArrayColumns& a : measured ? kMeasuredArrays : kTruthArrays) {
    std::vector<int> indexes;
    for (size_t i = 0; i < columns.size(); ++i)
      for (const std::string& name : a.names)
        if (!used[i] && Matches(columns[i], name)) indexes.push_back(take(static_cast<int>(i)));
    add_array(a.topic, std::move(indexes));
  }
  std::vector<int> other;
  for (size_t i = 0; i < columns.size(); ++i)
    if (!used[i]) other.push_back(static_cast<int>(i));
  add_array(measured ? "/exo/measured/other" : "/exo/truth/other", std::move(other));
  return log;
}

void BagLog::Row(const double* values, size_t n, const double* velocity) {
  auto value = [&](int i) { return i >= 0 && static_cast<size_t>(i) < n ? values[i] : 0.0; };
  const auto ns = static_cast<int64_t>(std::llround((values[0] + epoch_) * 1e9));
  mcap::McapWriter& w = bag_->writer_;
  if (!joints_.empty()) {
    position_.clear(), velocity_.clear(), effort_.clear();
    for (size_t j = 0; j < joints_.size(); ++j) {
      const Joint& jt = joints_[j];
      position_.push_back(value(jt.position));
      velocity_.push_back(jt.velocity >= 0 ? value(jt.velocity)
                          : velocity      ? velocity[j]
                                          : std::numeric_limits<double>::quiet_NaN());
      effort_.push_back(jt.effort_sign * value(jt.effort));
    }
    uint8_t* m = joint_message_.data();
    cdr::PatchTime(m + joint_layout_.stamp, ns);
    cdr::PatchFloat64s(m + joint_layout_.position, position_.data(), joints_.size());
    cdr::PatchFloat64s(m + joint_layout_.velocity, velocity_.data(), joints_.size());
    cdr::PatchFloat64s(m + joint_layout_.effort, effort_.data(), joints_.size());
    w.Write(joint_channel_, static_cast<uint64_t>(ns), static_cast<uint64_t>(ns), m, joint_message_.size());
  }
  for (Array& a : arrays_) {
    data_.clear();
    for (int i : a.columns) data_.push_back(value(i));
    cdr::PatchFloat64s(a.message.data() + a.data_at, data_.data(), data_.size());
    w.Write(a.channel, static_cast<uint64_t>(ns), static_cast<uint64_t>(ns), a.message.data(), a.message.size());
  }
}

}  // namespace exotwin
