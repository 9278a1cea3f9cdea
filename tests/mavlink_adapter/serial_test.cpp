// A drone flown by `eamos run` over a serial line to `eamos sim-vehicle`, both real processes:
// the line is two pseudo-terminals whose master sides this test joins byte for byte, as a
// cable joins the companion computer's UART to the autopilot's TELEM port. Each process opens
// its end by path with a serial:// URL, raw, at the rate the URL gives.
#include <gtest/gtest.h>

#include <poll.h>
#include <pty.h>
#include <signal.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <string>
#include <thread>

#include "support/eamos_process.h"
#include "support/run_eamos.h"
#include "support/scratch_dir.h"

namespace {

namespace fs = std::filesystem;

// Two pseudo-terminals joined at their masters: what is written to one end's slave is read
// from the other's. A thread copies until the cable is cut (destroyed).
class Cable {
 public:
  Cable() {
    for (End& e : ends_) {
      char name[256] = {};
      int slave = -1;
      if (openpty(&e.master, &slave, name, nullptr, nullptr) != 0) return;
      e.path = name;
      close(slave);
    }
    if (pipe(cut_) != 0) return;
    copier_ = std::thread([this] { copy(); });
  }
  ~Cable() {
    if (copier_.joinable()) {
      [[maybe_unused]] ssize_t n = write(cut_[1], "x", 1);
      copier_.join();
    }
    for (int fd : {ends_[0].master, ends_[1].master, cut_[0], cut_[1]})
      if (fd >= 0) close(fd);
  }
  bool ready() const { return copier_.joinable(); }
  const std::string& end(int i) const { return ends_[i].path; }

 private:
  struct End {
    int master = -1;
    std::string path;
  };
  void copy() {
    char buf[4096];
    for (;;) {
      pollfd fds[3] = {{ends_[0].master, POLLIN, 0}, {ends_[1].master, POLLIN, 0}, {cut_[0], POLLIN, 0}};
      if (poll(fds, 3, -1) < 0) continue;
      if (fds[2].revents) return;
      for (int i = 0; i < 2; ++i) {
        if (!(fds[i].revents & POLLIN)) continue;  // POLLHUP alone: that end is not open yet
        ssize_t n = read(ends_[i].master, buf, sizeof buf);
        for (ssize_t done = 0; n > 0 && done < n;) {
          ssize_t w = write(ends_[1 - i].master, buf + done, static_cast<size_t>(n - done));
          if (w <= 0) break;
          done += w;
        }
      }
    }
  }
  End ends_[2];
  int cut_[2] = {-1, -1};
  std::thread copier_;
};

TEST(MavlinkSerial, ADroneFliesItsMissionOverASerialLine) {
  Cable cable;
  ASSERT_TRUE(cable.ready());
  eamos_test::ScratchDir dir("serial");
  std::ofstream(dir / "hop.eamos") << "package hop\nvar Drone1 Quad\n"
                                      "func INIT() { Drone1.Arm(); Drone1.Takeoff(3); Drone1.Land(); Drone1.Disarm() }\n";
  std::ofstream(dir / "fleet.yaml") << "drones:\n  Drone1:\n    adapter: mavlink\n    connection: serial://"
                                    << cable.end(0) << ":921600\n    sysid: 1\n";
  eamos_test::EamosProcess vehicle = eamos_test::start_eamos(
      {"sim-vehicle", "--connection", "serial://" + cable.end(1) + ":921600", "--sysid", "1", "--speed", "4",
       "--duration", "120"});
  ASSERT_GT(vehicle.pid, 0);
  auto r = eamos_test::run_eamos("run " + (dir / "hop.eamos") + " --fleet " + (dir / "fleet.yaml") +
                                 " --speed 4 --trace " + (dir / "trace.jsonl"));
  kill(vehicle.pid, SIGTERM);
  eamos_test::wait_exit(vehicle);
  EXPECT_EQ(r.status, 0) << r.out;
  EXPECT_NE(r.out.find("Drone1.Takeoff(3)  succeeded"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("Drone1.Disarm()  succeeded"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("mission completed"), std::string::npos) << r.out;
}

}  // namespace
