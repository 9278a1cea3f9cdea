// Connection URLs are checked before any socket is opened, with errors that show valid ones.
#include <gtest/gtest.h>

#include "fleet/link_url.h"

namespace eamos::fleet {
namespace {

TEST(ConnectionUrl, UdpWithoutHostListensOnEveryAddress) {
  EndpointResult r = parse_link_url("udp://:14540");
  ASSERT_TRUE(r.endpoint) << r.error;
  EXPECT_EQ(r.endpoint->kind, LinkKind::udp_listen);
  EXPECT_EQ(r.endpoint->host, "");
  EXPECT_EQ(r.endpoint->port, 14540);
}

TEST(ConnectionUrl, UdpoutAndTcpNameThePeer) {
  EndpointResult out = parse_link_url("udpout://127.0.0.1:14550");
  ASSERT_TRUE(out.endpoint);
  EXPECT_EQ(out.endpoint->kind, LinkKind::udp_out);
  EXPECT_EQ(out.endpoint->host, "127.0.0.1");
  EndpointResult tcp = parse_link_url("tcp://localhost:5760");
  ASSERT_TRUE(tcp.endpoint);
  EXPECT_EQ(tcp.endpoint->kind, LinkKind::tcp_client);
  EXPECT_EQ(tcp.endpoint->port, 5760);
}

TEST(ConnectionUrl, SerialNamesTheDeviceAndItsRate) {
  EndpointResult r = parse_link_url("serial:///dev/ttyAMA0:921600");
  ASSERT_TRUE(r.endpoint) << r.error;
  EXPECT_EQ(r.endpoint->kind, LinkKind::serial);
  EXPECT_EQ(r.endpoint->device, "/dev/ttyAMA0");
  EXPECT_EQ(r.endpoint->baud, 921600u);
  EndpointResult by_id = parse_link_url("serial:///dev/serial/by-id/usb-ArduPilot_Pixhawk6C-if00:57600");
  ASSERT_TRUE(by_id.endpoint) << by_id.error;
  EXPECT_EQ(by_id.endpoint->device, "/dev/serial/by-id/usb-ArduPilot_Pixhawk6C-if00");
}

// Without a rate, or with one the UART cannot run at, the bytes would be garbage: refused.
TEST(ConnectionUrl, SerialWithoutAStandardRateOrAnAbsolutePathIsRefused) {
  EXPECT_NE(parse_link_url("serial:///dev/ttyUSB0").error.find("absolute path and its rate"), std::string::npos)
      << parse_link_url("serial:///dev/ttyUSB0").error;
  EXPECT_NE(parse_link_url("serial:///dev/ttyUSB0:").error.find("rate ''"), std::string::npos);
  EXPECT_NE(parse_link_url("serial:///dev/ttyUSB0:57601").error.find("is not a serial rate"), std::string::npos);
  EXPECT_NE(parse_link_url("serial://ttyUSB0:57600").error.find("absolute path"), std::string::npos);
  EXPECT_NE(parse_link_url("serial://").error.find("serial:///dev/ttyAMA0:921600"), std::string::npos);
}

TEST(ConnectionUrl, ErrorsSayWhatIsWrongAndShowExamples) {
  EXPECT_NE(parse_link_url("14540").error.find("no scheme"), std::string::npos);
  EXPECT_NE(parse_link_url("serial2:///dev/ttyUSB0").error.find("unknown scheme 'serial2'"), std::string::npos);
  EXPECT_NE(parse_link_url("udp://:0").error.find("from 1 to 65535"), std::string::npos);
  EXPECT_NE(parse_link_url("udp://:70000").error.find("from 1 to 65535"), std::string::npos);
  EXPECT_NE(parse_link_url("udp://:14x").error.find("'14x'"), std::string::npos);
  EXPECT_NE(parse_link_url("tcp://:5760").error.find("needs the peer's host"), std::string::npos);
  EXPECT_NE(parse_link_url("udp://localhost").error.find("no port"), std::string::npos);
  EXPECT_NE(parse_link_url("udp://:1").error, "x");  // valid: no error text at all
  EXPECT_EQ(parse_link_url("udp://:1").error, "");
  EXPECT_NE(parse_link_url("tcp://").error.find("udpout://127.0.0.1:14550"), std::string::npos);
}

}  // namespace
}  // namespace eamos::fleet
