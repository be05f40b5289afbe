#include "protocol/candump_replay_bus.h"

#include <algorithm>

namespace exotwin {

CandumpReplayBus::CandumpReplayBus(std::vector<CanFrame> frames, std::vector<uint16_t> accept_ids)
    : frames_(std::move(frames)), accept_(std::move(accept_ids)) {
  std::stable_sort(frames_.begin(), frames_.end(), [](const CanFrame& a, const CanFrame& b) { return a.t < b.t; });
}

std::unique_ptr<CandumpReplayBus> CandumpReplayBus::FromLog(const std::string& path, const std::string& interface,
                                                            int64_t epoch_s, std::vector<uint16_t> accept_ids) {
  std::vector<CanFrame> frames;
  for (const CandumpRecord& r : CandumpReader::ReadAll(path, epoch_s))
    if (interface.empty() || r.interface == interface) frames.push_back(r.frame);
  return std::make_unique<CandumpReplayBus>(std::move(frames), std::move(accept_ids));
}

CanStatus CandumpReplayBus::Send(const CanFrame& frame) {
  if (!IsValidDataFrame(frame)) return CanStatus::kError;
  CanFrame f = frame;
  f.t = now_;
  sent_.push_back(f);
  if (writer_) {
    try {
      writer_->Write(f);
    } catch (...) {
      return CanStatus::kError;
    }
  }
  return CanStatus::kOk;
}

CanStatus CandumpReplayBus::Receive(CanFrame* out) {
  while (next_ < frames_.size() && frames_[next_].t <= now_) {
    const CanFrame& f = frames_[next_++];
    const bool accepted =
        f.error || accept_.empty() || std::find(accept_.begin(), accept_.end(), f.id) != accept_.end();
    if (!accepted) continue;
    *out = f;
    return f.error ? CanStatus::kError : CanStatus::kOk;
  }
  return CanStatus::kNoFrame;
}

}  // namespace exotwin
