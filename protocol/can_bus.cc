#include "protocol/can_bus.h"

namespace exotwin {

CanBus::~CanBus() = default;

const char* CanStatusName(CanStatus s) {
  switch (s) {
    case CanStatus::kOk: return "ok";
    case CanStatus::kQueueFull: return "queue_full";
    case CanStatus::kBusOff: return "bus_off";
    case CanStatus::kNoFrame: return "no_frame";
    case CanStatus::kError: return "error";
  }
  return "unknown";
}

}  // namespace exotwin
