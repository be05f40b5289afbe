// A run written as a ROS 2 bag (RunOptions::mcap; DESIGN.md "ROS 2 bags (MCAP) in and out"): one MCAP
// file (formats/mcap_writer.h, profile ros2, CDR messages with ros2msg schemas, zstd chunks) holding
// every row of the run's logs (measured[_trialN].csv and truth[_trialN].csv) as messages on the
// topics below, stamped with the run's clock (header.stamp and log_time = publish_time, ns; the
// trials follow each other as in the CAN log: trial i at i (duration + 1 s)), and a metadata record
// "exotwin" naming the scenario and its seed.
//
// Topics of the measured log (the rig's view):
//   /exo/joint_states   sensor_msgs/msg/JointState  name [hip, knee] (HAL-3: [knee]); position q_*,
//                       velocity the controller's estimate (NaN when unknown), effort -tau_* (the
//                       actuator torque -tau_S)
//   /exo/command, /exo/reference, /exo/emg, /exo/safety_state, /exo/assist (HAL-3)
//                       std_msgs/msg/Float64MultiArray: data the log's cmd_*, ref_*, emg_*, state, and
//                       E_ext E_flex mu_hat D_hat K_hat columns in order; layout.dim[0].label the
//                       column names joined by ','
// Topics of the truth log (the plant's):
//   /exo/truth/joint_states  JointState: position, velocity, effort = the applied actuator torque
//                       (q_*, qd_*, tau_R_*; HAL-3: th, thd, tau_motor as the knee)
//   /exo/truth/muscle_torque (tau_M_*, HAL-3 tau_muscle), /exo/truth/human (HAL-3: tau_interaction,
//                       D_true, K_true, mu_contraction): Float64MultiArray as above
// A column no topic names goes to /exo/measured/other or /exo/truth/other (Float64MultiArray), so a
// bag always holds every value its CSV logs hold.
#pragma once
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "formats/cdr_writer.h"
#include "formats/mcap_writer.h"
#include "runner/scenario.h"

namespace exotwin {

enum class BagLogKind { kMeasured, kTruth };

class RunBag;

// One log of a trial in the bag: each Row becomes one message on each of its topics.
class BagLog {
 public:
  // values[0..n) a row of the log's columns (values[0] = t, s; missing columns 0, as the CSV); `velocity`
  // the measured JointState's velocity, one per joint in the message's order (null: NaN, unknown).
  void Row(const double* values, size_t n, const double* velocity = nullptr);

 private:
  friend class RunBag;
  struct Joint {
    std::string name;
    int position = -1, velocity = -1, effort = -1;  // column indexes (-1: none)
    double effort_sign = 1;
  };
  // Each topic's message encoded once (its names and labels fixed); a row overwrites its stamp and
  // values (cdr::JointStateLayout).
  struct Array {
    uint16_t channel = 0;
    std::vector<int> columns;
    std::vector<uint8_t> message;
    size_t data_at = 0;
  };
  RunBag* bag_ = nullptr;
  double epoch_ = 0;
  uint16_t joint_channel_ = 0;
  std::vector<Joint> joints_;
  std::vector<uint8_t> joint_message_;
  cdr::JointStateLayout joint_layout_;
  std::vector<Array> arrays_;
  std::vector<double> position_, velocity_, effort_, data_;  // one row's fields, reused
};

class RunBag {
 public:
  // Creates `path` (InputError if it cannot be written) with the metadata record of scenario `s` run
  // on `seed`.
  RunBag(const std::string& path, const Scenario& s, uint64_t seed);
  // The bag's log of `kind` with `columns` (columns[0] = "t"), its stamps shifted by `epoch` s.
  std::unique_ptr<BagLog> Open(BagLogKind kind, const std::vector<std::string>& columns, double epoch);
  // Writes the last chunk, the summary and the footer (the destructor does it too, reporting errors).
  void Close() { writer_.Close(); }

 private:
  friend class BagLog;
  uint16_t Channel(const std::string& topic, bool joint_state);  // one channel per topic for all trials
  mcap::McapWriter writer_;
  uint16_t joint_state_schema_ = 0, array_schema_ = 0;
  std::vector<std::pair<std::string, uint16_t>> channels_;
};

}  // namespace exotwin
