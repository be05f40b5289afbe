#include "hwsim/virtual_can_bus.h"

#include <algorithm>
#include <limits>

#include "protocol/can_bits.h"

namespace exotwin::hwsim {
namespace {
constexpr int kTecBusOff = 255;        // bus-off when TEC exceeds this
constexpr int kPassiveLimit = 128;     // error passive when TEC or REC reaches this
constexpr int kRecoveryBits = 128 * 11;  // bus-off recovery: 128 occurrences of 11 recessive bits
}  // namespace

// ---- Endpoint ----

VirtualCanBus::Endpoint::Endpoint(VirtualCanBus* bus, std::string name, const std::vector<uint16_t>& accept,
                                  size_t index)
    : bus_(bus), name_(std::move(name)), index_(index) {
  if (accept.empty()) accept_.set();
  for (uint16_t id : accept)
    if (id <= kCanMaxId) accept_.set(id);
}

bool VirtualCanBus::Endpoint::Accepts(uint16_t id) const { return id <= kCanMaxId && accept_.test(id); }

void VirtualCanBus::Endpoint::UpdateState() {
  if (state_ == CanNodeState::kBusOff) return;
  state_ = (tec_ >= kPassiveLimit || rec_ >= kPassiveLimit) ? CanNodeState::kErrorPassive
                                                           : CanNodeState::kErrorActive;
}

void VirtualCanBus::Endpoint::EnterBusOff(double t) {
  state_ = CanNodeState::kBusOff;
  tec_ = std::max(tec_, kTecBusOff + 1);
  tx_.clear();
  recover_at_ = t + kRecoveryBits / bus_->config_.bitrate;
}

void VirtualCanBus::Endpoint::ForceBusOff() { EnterBusOff(bus_->now_); }

void VirtualCanBus::Endpoint::RecoverBusOff() {
  state_ = CanNodeState::kErrorActive;
  tec_ = rec_ = 0;
}

CanStatus VirtualCanBus::Endpoint::Send(const CanFrame& frame) {
  if (!IsValidDataFrame(frame)) return CanStatus::kError;
  if (state_ == CanNodeState::kBusOff) return CanStatus::kBusOff;
  if (tx_.size() >= bus_->config_.tx_queue_limit) {
    ++bus_->stats_.queue_full;
    return CanStatus::kQueueFull;
  }
  CanFrame f = frame;
  for (int i = f.dlc; i < 8; ++i) f.data[i] = 0;
  f.t = bus_->now_;
  tx_.push_back({f, bus_->now_});
  return CanStatus::kOk;
}

CanStatus VirtualCanBus::Endpoint::Receive(CanFrame* out) {
  if (rx_.empty() || rx_.front().t > bus_->now_) return CanStatus::kNoFrame;
  *out = rx_.front();
  rx_.pop_front();
  ++received_;
  return out->error ? CanStatus::kError : CanStatus::kOk;
}

// ---- Bus ----

VirtualCanBus::VirtualCanBus(const VirtualCanBusConfig& config) : config_(config), rng_(config.seed) {}

VirtualCanBus::Endpoint* VirtualCanBus::AddNode(std::string name, std::vector<uint16_t> accept_ids) {
  nodes_.push_back(std::unique_ptr<Endpoint>(new Endpoint(this, std::move(name), accept_ids, nodes_.size())));
  return nodes_.back().get();
}

double VirtualCanBus::FrameDuration(const CanFrame& frame, double bitrate) {
  return CanFrameBits(frame) / bitrate;
}

void VirtualCanBus::AdvanceTo(double t) {
  if (t < now_) t = now_;
  for (;;) {
    // Earliest moment a queued frame can start: the bus idle and the frame queued.
    double earliest = std::numeric_limits<double>::infinity();
    for (const auto& n : nodes_)
      if (!n->tx_.empty()) earliest = std::min(earliest, n->tx_.front().ready);
    const double start = std::max(bus_free_at_, earliest);
    if (!(start < t)) break;  // nothing pending, or it starts at/after t (later Sends may still join)
    // Arbitration among the queue heads ready at start: lowest ID, then first-added node.
    Endpoint* winner = nullptr;
    for (const auto& n : nodes_) {
      if (n->tx_.empty() || n->tx_.front().ready > start) continue;
      if (!winner || n->tx_.front().frame.id < winner->tx_.front().frame.id) winner = n.get();
    }
    Transmit(winner, start);
  }
  now_ = t;
  if (config_.auto_bus_off_recovery)
    for (const auto& n : nodes_)
      if (n->state_ == CanNodeState::kBusOff && n->recover_at_ <= now_) n->RecoverBusOff();
  while (!busy_.empty() && busy_.front().end < now_ - config_.load_window) busy_.pop_front();
}

void VirtualCanBus::Transmit(Endpoint* node, double start) {
  const double bit = 1.0 / config_.bitrate;
  const CanFrame frame = node->tx_.front().frame;
  const int bits = CanFrameBits(frame);
  const bool corrupt = config_.corrupt_probability > 0 && rng_.Uniform() < config_.corrupt_probability;
  if (corrupt) {
    // A bit error caught by the CRC check: the receivers signal it after the ACK delimiter with an
    // error flag (6) + delimiter (8), then the intermission; the transmitter retries the frame.
    const int stuffed = bits - kCanTrailerBits - kCanIfsBits;
    const int total = stuffed + 3 + kCanErrorFrameBits + kCanIfsBits;
    const double end = start + total * bit;
    bus_free_at_ = end;
    AddBusy(start, end);
    ++stats_.error_frames;
    stats_.bits += static_cast<uint64_t>(total);
    node->tec_ += 8;
    for (const auto& n : nodes_)
      if (n.get() != node && n->state_ != CanNodeState::kBusOff) {
        n->rec_ = std::min(n->rec_ + 1, 255);
        n->UpdateState();
      }
    node->UpdateState();
    if (node->tec_ > kTecBusOff) node->EnterBusOff(end);
    CanFrame err;
    err.error = true;
    err.t = end - kCanIfsBits * bit;
    if (tap_) tap_(err);
    if (config_.deliver_error_frames)
      for (const auto& n : nodes_)
        if (n->state_ != CanNodeState::kBusOff || n.get() == node) Deliver(n.get(), err, err.t, false);
    return;
  }
  node->tx_.pop_front();
  ++node->sent_;
  node->tec_ = std::max(0, node->tec_ - 1);
  node->UpdateState();
  const double end = start + bits * bit;
  const double eof_end = end - kCanIfsBits * bit;
  bus_free_at_ = end;
  AddBusy(start, end);
  ++stats_.frames;
  stats_.bits += static_cast<uint64_t>(bits);
  CanFrame wire = frame;
  wire.t = eof_end;
  if (tap_) tap_(wire);
  for (const auto& n : nodes_) {
    if (n.get() == node || n->state_ == CanNodeState::kBusOff) continue;
    n->rec_ = std::max(0, n->rec_ - 1);
    n->UpdateState();
    if (n->Accepts(frame.id)) Deliver(n.get(), wire, eof_end, true);
  }
}

void VirtualCanBus::Deliver(Endpoint* to, const CanFrame& frame, double at, bool random_faults) {
  double when = at + config_.latency;
  if (random_faults) {
    if (config_.drop_probability > 0 && rng_.Uniform() < config_.drop_probability) {
      ++stats_.drops;
      ++to->dropped_;
      return;
    }
    if (config_.jitter > 0) when += config_.jitter * rng_.Uniform();
    if (config_.spike_probability > 0 && rng_.Uniform() < config_.spike_probability) {
      when += config_.spike_delay;
      ++stats_.spikes;
    }
  }
  if (to->rx_.size() >= config_.rx_queue_limit) {
    ++stats_.drops;
    ++to->dropped_;
    return;
  }
  if (!to->rx_.empty()) when = std::max(when, to->rx_.back().t);  // a FIFO: never reorders
  CanFrame f = frame;
  f.t = when;
  to->rx_.push_back(f);
}

void VirtualCanBus::AddBusy(double start, double end) {
  busy_.push_back({start, end});
  stats_.busy_time += end - start;
}

CanBusStatistics VirtualCanBus::Statistics() const {
  CanBusStatistics s = stats_;
  // Remove the part of the last transmission that lies beyond now.
  if (!busy_.empty() && busy_.back().end > now_) s.busy_time -= busy_.back().end - std::max(busy_.back().start, now_);
  const double w0 = std::max(0.0, now_ - config_.load_window);
  double busy = 0;
  for (size_t i = 0; i < busy_.size(); ++i)
    busy += std::max(0.0, std::min(busy_[i].end, now_) - std::max(busy_[i].start, w0));
  const double window = now_ - w0;
  s.load_percent = window > 0 ? 100.0 * busy / window : 0.0;
  s.mean_load_percent = now_ > 0 ? 100.0 * s.busy_time / now_ : 0.0;
  return s;
}

}  // namespace exotwin::hwsim
