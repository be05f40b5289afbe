// The SocketCAN backend builds and fails cleanly at set-up where there is no such interface (CI has
// no CAN hardware; its real send/receive path is exercised on a rig with vcan/can0 only).
#include "protocol/socketcan_bus.h"

#include <gtest/gtest.h>

#include "core/error.h"

namespace exotwin {
namespace {

TEST(SocketCanBus, NonexistentInterfaceThrowsInputErrorNamingIt) {
  try {
    SocketCanBus::Open("exotwin_nocan9");
    FAIL() << "opened a nonexistent interface";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("exotwin_nocan9"), std::string::npos) << e.what();
  }
  EXPECT_THROW(SocketCanBus::Open(""), InputError);
  EXPECT_THROW(SocketCanBus::Open("an_interface_name_far_too_long"), InputError);
}

}  // namespace
}  // namespace exotwin
