// Links carry frames both ways over loopback sockets; handlers run on the link's thread, so
// the tests hand frames over through a small mailbox and wait for them with a deadline.
#include <gtest/gtest.h>

#include <arpa/inet.h>
#include <netinet/in.h>
#include <fcntl.h>
#include <pty.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <sys/socket.h>
#include <unistd.h>

#include <chrono>
#include <condition_variable>
#include <mutex>
#include <stdexcept>
#include <vector>

#include "mavlink/link.h"
#include "mavlink/payloads.h"

namespace eamos::mavlink {
namespace {

struct Mailbox {
  std::mutex m;
  std::condition_variable cv;
  std::vector<Frame> frames;

  FrameHandler handler() {
    return [this](Frame f) {
      std::lock_guard lock(m);
      frames.push_back(std::move(f));
      cv.notify_all();
    };
  }
  /// Waits until `n` frames arrived; the deadline only guards against a broken link.
  bool wait_for(size_t n) {
    std::unique_lock lock(m);
    return cv.wait_for(lock, std::chrono::seconds(5), [&] { return frames.size() >= n; });
  }
};

fleet::Endpoint endpoint(const std::string& url) { return *fleet::parse_link_url(url).endpoint; }

TEST(UdpLink, ListenerRepliesToTheLastSender) {
  Mailbox vehicle_side, adapter_side;
  OpenResult listen = Link::open(endpoint("udp://127.0.0.1:25301"), adapter_side.handler());
  ASSERT_TRUE(listen.link) << listen.error;
  OpenResult out = Link::open(endpoint("udpout://127.0.0.1:25301"), vehicle_side.handler());
  ASSERT_TRUE(out.link) << out.error;

  Heartbeat hb;
  hb.custom_mode = 42;
  EXPECT_FALSE(listen.link->send(Encoder{}.encode(pack(hb))));  // nobody has spoken yet
  Encoder vehicle{7, 1};
  ASSERT_TRUE(out.link->send(vehicle.encode(pack(hb))));
  ASSERT_TRUE(adapter_side.wait_for(1));
  EXPECT_EQ(adapter_side.frames[0].sysid, 7);
  EXPECT_EQ(unpack_heartbeat(adapter_side.frames[0].message)->custom_mode, 42u);

  Encoder adapter{7, 191};
  ASSERT_TRUE(listen.link->send(adapter.encode(pack(CommandAck{400, 0}))));
  ASSERT_TRUE(vehicle_side.wait_for(1));
  EXPECT_EQ(vehicle_side.frames[0].compid, 191);
  EXPECT_EQ(unpack_command_ack(vehicle_side.frames[0].message)->command, 400);
}

TEST(UdpLink, ListenerIgnoresAGarbageDatagramAndOtherSystemsFromAnotherAddress) {
  Mailbox adapter_side, vehicle_side, stranger_side;
  OpenResult listen = Link::open(endpoint("udp://127.0.0.1:25303"), adapter_side.handler());
  ASSERT_TRUE(listen.link) << listen.error;
  listen.link->follow_only(7);
  OpenResult vehicle = Link::open(endpoint("udpout://127.0.0.1:25303"), vehicle_side.handler());
  OpenResult stranger = Link::open(endpoint("udpout://127.0.0.1:25303"), stranger_side.handler());
  ASSERT_TRUE(vehicle.link && stranger.link);

  Encoder vehicle_enc{7, 1}, stranger_enc{99, 1}, adapter{7, 191};
  ASSERT_TRUE(vehicle.link->send(vehicle_enc.encode(pack(Heartbeat{}))));
  ASSERT_TRUE(adapter_side.wait_for(1));

  // From another port: a datagram of garbage (with a MAVLink v2 start byte in it), then
  // a valid frame of another system. Both are dropped unread: the vehicle's next frame is
  // the adapter's second.
  std::vector<uint8_t> garbage = {0xFD, 0x09, 0x00, 0x00, 0x01, 0x07, 0x01, 0x00, 0x00, 0x00, 0xAA, 0x55};
  ASSERT_TRUE(stranger.link->send(garbage));
  ASSERT_TRUE(stranger.link->send(stranger_enc.encode(pack(Heartbeat{}))));
  ASSERT_TRUE(vehicle.link->send(vehicle_enc.encode(pack(Heartbeat{}))));
  ASSERT_TRUE(adapter_side.wait_for(2));
  EXPECT_EQ(adapter_side.frames[1].sysid, 7);
  EXPECT_EQ(listen.link->foreign_datagrams(), 2u);

  // Replies still go to the vehicle: it gets the ACK, so the stranger did not.
  ASSERT_TRUE(listen.link->send(adapter.encode(pack(CommandAck{400, 0}))));
  ASSERT_TRUE(vehicle_side.wait_for(1));
  EXPECT_EQ(unpack_command_ack(vehicle_side.frames[0].message)->command, 400);

  std::lock_guard lock(stranger_side.m);
  EXPECT_TRUE(stranger_side.frames.empty());
}

TEST(UdpLink, ListenerKeepsTheVehiclesAddressAndCountsFramesFromAnyOther) {
  Mailbox adapter_side, vehicle_side, forger_side;
  OpenResult listen = Link::open(endpoint("udp://127.0.0.1:25305"), adapter_side.handler());
  ASSERT_TRUE(listen.link) << listen.error;
  listen.link->follow_only(7);
  OpenResult vehicle = Link::open(endpoint("udpout://127.0.0.1:25305"), vehicle_side.handler());
  OpenResult forger = Link::open(endpoint("udpout://127.0.0.1:25305"), forger_side.handler());
  ASSERT_TRUE(vehicle.link && forger.link);
  Encoder vehicle_enc{7, 1}, forged_enc{7, 1}, adapter{7, 191};
  ASSERT_TRUE(vehicle.link->send(vehicle_enc.encode(pack(Heartbeat{}))));
  ASSERT_TRUE(adapter_side.wait_for(1));
  EXPECT_TRUE(listen.link->locked());

  // Valid frames with the vehicle's own system id, from another port: a forged DENIED ACK
  // and a HEARTBEAT. Neither reaches the adapter, and neither moves the link.
  ASSERT_TRUE(forger.link->send(forged_enc.encode(pack(CommandAck{400, 2}))));
  ASSERT_TRUE(forger.link->send(forged_enc.encode(pack(Heartbeat{}))));
  // The vehicle's next frame comes after them on the same loopback path: when it is in, the
  // forged ones were read (and dropped) before it.
  Heartbeat marker;
  marker.custom_mode = 5;
  ASSERT_TRUE(vehicle.link->send(vehicle_enc.encode(pack(marker))));
  ASSERT_TRUE(adapter_side.wait_for(2));
  {
    std::lock_guard lock(adapter_side.m);
    ASSERT_EQ(adapter_side.frames.size(), 2u);
    EXPECT_EQ(unpack_heartbeat(adapter_side.frames[1].message)->custom_mode, 5u);
  }
  EXPECT_EQ(listen.link->foreign_datagrams(), 2u);
  ASSERT_TRUE(listen.link->send(adapter.encode(pack(CommandAck{176, 0}))));
  ASSERT_TRUE(vehicle_side.wait_for(1));
  EXPECT_EQ(unpack_command_ack(vehicle_side.frames[0].message)->command, 176);
  std::lock_guard lock(forger_side.m);
  EXPECT_TRUE(forger_side.frames.empty());
}

TEST(UdpLink, ListenerBeforeTheVehicleIsKnownFollowsTheLastValidFrameOfAnySystem) {
  Mailbox adapter_side, a_side, b_side;
  OpenResult listen = Link::open(endpoint("udp://127.0.0.1:25304"), adapter_side.handler());
  ASSERT_TRUE(listen.link) << listen.error;
  OpenResult a = Link::open(endpoint("udpout://127.0.0.1:25304"), a_side.handler());
  OpenResult b = Link::open(endpoint("udpout://127.0.0.1:25304"), b_side.handler());
  ASSERT_TRUE(a.link && b.link);
  Encoder a_enc{3, 1}, b_enc{4, 1}, adapter{1, 191};
  ASSERT_TRUE(b.link->send(std::vector<uint8_t>(40, 0xFD)));  // garbage: nobody to reply to yet
  EXPECT_FALSE(listen.link->send(adapter.encode(pack(CommandAck{1, 0}))));
  ASSERT_TRUE(a.link->send(a_enc.encode(pack(Heartbeat{}))));
  ASSERT_TRUE(adapter_side.wait_for(1));
  ASSERT_TRUE(listen.link->send(adapter.encode(pack(CommandAck{400, 0}))));
  ASSERT_TRUE(a_side.wait_for(1));
  ASSERT_TRUE(b.link->send(b_enc.encode(pack(Heartbeat{}))));
  ASSERT_TRUE(adapter_side.wait_for(2));
  ASSERT_TRUE(listen.link->send(adapter.encode(pack(CommandAck{176, 0}))));
  ASSERT_TRUE(b_side.wait_for(1));
  EXPECT_EQ(unpack_command_ack(b_side.frames[0].message)->command, 176);
}

// The frame handler runs on the link's own thread: an exception escaping it would end the
// process (std::terminate) with the vehicle in flight. That datagram is dropped and the link
// goes on.
TEST(UdpLink, HandlerThatThrowsLosesOnlyThatDatagram) {
  Mailbox got;
  int calls = 0;
  FrameHandler throwing_once = [&calls, inner = got.handler()](Frame f) {
    if (++calls == 1) throw std::runtime_error("bad frame");
    inner(std::move(f));
  };
  OpenResult listen = Link::open(endpoint("udp://127.0.0.1:25306"), throwing_once);
  ASSERT_TRUE(listen.link) << listen.error;
  Mailbox ignored;
  OpenResult out = Link::open(endpoint("udpout://127.0.0.1:25306"), ignored.handler());
  ASSERT_TRUE(out.link) << out.error;
  Encoder vehicle{7, 1};
  Heartbeat hb;
  ASSERT_TRUE(out.link->send(vehicle.encode(pack(hb))));
  hb.custom_mode = 2;
  ASSERT_TRUE(out.link->send(vehicle.encode(pack(hb))));
  ASSERT_TRUE(got.wait_for(1));
  EXPECT_EQ(unpack_heartbeat(got.frames[0].message)->custom_mode, 2u);
}

TEST(UdpLink, PortInUseIsAClearError) {
  Mailbox a;
  OpenResult first = Link::open(endpoint("udp://127.0.0.1:25302"), a.handler());
  ASSERT_TRUE(first.link);
  // Two adapters on one port would each see half of the vehicle's datagrams.
  OpenResult second = Link::open(endpoint("udp://127.0.0.1:25302"), a.handler());
  EXPECT_FALSE(second.link);
  EXPECT_NE(second.error.find("udp://127.0.0.1:25302"), std::string::npos) << second.error;
  EXPECT_NE(second.error.find("bind"), std::string::npos) << second.error;
}

/// A one-connection TCP server on loopback, standing in for ArduPilot SITL's port 5760.
struct TcpServer {
  int listener = -1;
  explicit TcpServer(uint16_t port) {
    listener = socket(AF_INET, SOCK_STREAM, 0);
    int yes = 1;
    setsockopt(listener, SOL_SOCKET, SO_REUSEADDR, &yes, sizeof yes);
    sockaddr_in a{};
    a.sin_family = AF_INET;
    a.sin_port = htons(port);
    a.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
    bind(listener, reinterpret_cast<sockaddr*>(&a), sizeof a);
    listen(listener, 1);
  }
  ~TcpServer() { close(listener); }
};

TEST(TcpLink, CarriesFramesBothWaysInAnyChunking) {
  TcpServer server(25304);
  Mailbox adapter_side;
  OpenResult r = Link::open(endpoint("tcp://127.0.0.1:25304"), adapter_side.handler());
  ASSERT_TRUE(r.link) << r.error;
  int conn = accept(server.listener, nullptr, nullptr);
  ASSERT_GE(conn, 0);

  // Two frames written as three pieces: TCP is a byte stream, not a message stream.
  Encoder vehicle{3, 1};
  std::vector<uint8_t> bytes = vehicle.encode(pack(Heartbeat{}));
  std::vector<uint8_t> second = vehicle.encode(pack(ExtendedSysState{0, 2}));
  bytes.insert(bytes.end(), second.begin(), second.end());
  ASSERT_EQ(write(conn, bytes.data(), 5), 5);
  ASSERT_EQ(write(conn, bytes.data() + 5, 12), 12);
  ASSERT_EQ(write(conn, bytes.data() + 17, bytes.size() - 17), ssize_t(bytes.size() - 17));
  ASSERT_TRUE(adapter_side.wait_for(2));
  EXPECT_EQ(unpack_extended_sys_state(adapter_side.frames[1].message)->landed_state, 2);

  std::vector<uint8_t> ack = Encoder{3, 191}.encode(pack(CommandAck{22, 0}));
  ASSERT_TRUE(r.link->send(ack));
  std::vector<uint8_t> got(ack.size());
  ASSERT_EQ(read(conn, got.data(), got.size()), ssize_t(ack.size()));
  EXPECT_EQ(got, ack);
  close(conn);
}

TEST(TcpLink, ReconnectsAfterThePeerClosed) {
  TcpServer server(25305);
  Mailbox adapter_side;
  OpenResult r = Link::open(endpoint("tcp://127.0.0.1:25305"), adapter_side.handler(), 0.01);
  ASSERT_TRUE(r.link) << r.error;
  int first = accept(server.listener, nullptr, nullptr);
  ASSERT_GE(first, 0);
  close(first);  // the SITL restarted
  // accept() blocks until the link dials again.
  int second = accept(server.listener, nullptr, nullptr);
  ASSERT_GE(second, 0);
  std::vector<uint8_t> hb = Encoder{3, 1}.encode(pack(Heartbeat{}));
  ASSERT_EQ(write(second, hb.data(), hb.size()), ssize_t(hb.size()));
  ASSERT_TRUE(adapter_side.wait_for(1));
  EXPECT_EQ(adapter_side.frames[0].sysid, 3);
  close(second);
}

// A serial port: the kernel's pseudo-terminal, a real tty with termios (openpty). The test
// holds the master side, where the autopilot's UART would be.
struct Pty {
  int master = -1;
  std::string slave_path;
  Pty() {
    int slave = -1;
    char name[256] = {};
    if (openpty(&master, &slave, name, nullptr, nullptr) == 0) {
      slave_path = name;
      close(slave);  // the link opens it by its path, as a user's URL names it
    }
  }
  ~Pty() {
    if (master >= 0) close(master);
  }
};

TEST(SerialLink, CarriesFramesBothWaysOverATerminalInRawMode) {
  Pty pty;
  ASSERT_GE(pty.master, 0);
  Mailbox adapter_side;
  OpenResult r = Link::open(endpoint("serial://" + pty.slave_path + ":921600"), adapter_side.handler());
  ASSERT_TRUE(r.link) << r.error;

  // Bytes a line discipline would change (CR, NL, ^C, ^D, 0xFF) arrive untouched: raw mode.
  Encoder vehicle{3, 1};
  std::vector<uint8_t> bytes = vehicle.encode(pack(Statustext{6, "\r\n\x03\x04\xff", 0, 0}));
  std::vector<uint8_t> second = vehicle.encode(pack(Heartbeat{}));
  bytes.insert(bytes.end(), second.begin(), second.end());
  ASSERT_EQ(write(pty.master, bytes.data(), 7), 7);
  ASSERT_EQ(write(pty.master, bytes.data() + 7, bytes.size() - 7), ssize_t(bytes.size() - 7));
  ASSERT_TRUE(adapter_side.wait_for(2));
  EXPECT_EQ(adapter_side.frames[1].sysid, 3);
  EXPECT_EQ(r.link->stats().bad_crc, 0u);

  std::vector<uint8_t> ack = Encoder{3, 191}.encode(pack(CommandAck{22, 0}));
  ASSERT_TRUE(r.link->send(ack));
  std::vector<uint8_t> got(ack.size());
  size_t have = 0;
  while (have < got.size()) {
    ssize_t n = read(pty.master, got.data() + have, got.size() - have);
    ASSERT_GT(n, 0);
    have += static_cast<size_t>(n);
  }
  EXPECT_EQ(got, ack);
}

// The autopilot's end stops reading (hung, a USB bridge stalled): once the port's buffer is
// full a frame is dropped and send() says so at once, instead of blocking the event loop
// that sends it. A blocking port would hang here.
TEST(SerialLink, AFullPortDropsAFrameInsteadOfBlockingTheSender) {
  Pty pty;
  ASSERT_GE(pty.master, 0);
  Mailbox a;
  OpenResult r = Link::open(endpoint("serial://" + pty.slave_path + ":57600"), a.handler());
  ASSERT_TRUE(r.link) << r.error;
  std::vector<uint8_t> frame = Encoder{3, 191}.encode(pack(Heartbeat{}));
  int sent = 0;
  while (sent < 1000000 && r.link->send(frame)) ++sent;
  EXPECT_LT(sent, 1000000) << "every frame went out although nobody read the port";
  EXPECT_GT(sent, 0);
}

// The errno of opening `path` read-write as user `uid` (root may open a port held
// exclusively, another user may not), from a child process that becomes that user.
int open_errno_as(const std::string& path, uid_t uid) {
  pid_t child = fork();
  if (child == 0) {
    if (setgid(uid) != 0 || setuid(uid) != 0) _exit(255);
    int fd = ::open(path.c_str(), O_RDWR | O_NOCTTY);
    _exit(fd >= 0 ? 0 : errno);
  }
  int status = 0;
  waitpid(child, &status, 0);
  return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
}

// A port is the link's alone: a second program opening it would take half of the bytes.
TEST(SerialLink, ASecondOpenOfThePortIsRefusedWhileTheLinkHoldsIt) {
  Pty pty;
  ASSERT_GE(pty.master, 0);
  ASSERT_EQ(chmod(pty.slave_path.c_str(), 0666), 0);
  const uid_t nobody = 65534;
  ASSERT_EQ(open_errno_as(pty.slave_path, nobody), 0) << "before the link holds it, anyone may open it";
  Mailbox a;
  OpenResult link = Link::open(endpoint("serial://" + pty.slave_path + ":57600"), a.handler());
  ASSERT_TRUE(link.link) << link.error;
  EXPECT_EQ(open_errno_as(pty.slave_path, nobody), EBUSY);
}

TEST(SerialLink, AFileThatIsNoSerialPortIsRefusedByName) {
  Mailbox a;
  OpenResult null = Link::open(endpoint("serial:///dev/null:57600"), a.handler());
  EXPECT_FALSE(null.link);
  EXPECT_NE(null.error.find("/dev/null is not a serial port"), std::string::npos) << null.error;
  OpenResult missing = Link::open(endpoint("serial:///dev/ttyEAMOS9:57600"), a.handler());
  EXPECT_FALSE(missing.link);
  EXPECT_NE(missing.error.find("No such file or directory"), std::string::npos) << missing.error;
}

TEST(TcpLink, RefusedConnectionNamesTheUrl) {
  Mailbox a;
  OpenResult r = Link::open(endpoint("tcp://127.0.0.1:25303"), a.handler());
  EXPECT_FALSE(r.link);
  EXPECT_NE(r.error.find("tcp://127.0.0.1:25303"), std::string::npos) << r.error;
  EXPECT_NE(r.error.find("refused"), std::string::npos) << r.error;
}

}  // namespace
}  // namespace eamos::mavlink
