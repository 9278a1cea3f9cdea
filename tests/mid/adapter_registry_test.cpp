// The Adapter Space registry: adapters by name; an unknown name is an error value that
// lists the known ones.
#include "mid/adapter_registry.h"

#include <gtest/gtest.h>

namespace eamos::mid {
namespace {

// The smallest Drone: enough to see which factory made it.
class FakeDrone final : public Drone {
 public:
  explicit FakeDrone(std::string name) : name_(std::move(name)) {}
  const std::string& name() const override { return name_; }
  ActionId start(const ActionRequest&, EndCallback) override { return 1; }
  bool cancel(ActionId) override { return false; }
  DroneState state() const override { return {}; }
  SubscriptionId subscribe(StateCallback) override { return 1; }
  void unsubscribe(SubscriptionId) override {}
  void failsafe(fleet::Failsafe) override {}

 private:
  std::string name_;
};

AdapterFactory fake_factory(std::string tag) {
  return [tag](const fleet::DroneSettings& s, const fleet::DroneType&, EventLoop&) {
    return CreateResult{CreateStatus::success, std::make_unique<FakeDrone>(tag + ":" + s.name), ""};
  };
}

fleet::DroneSettings settings() {
  fleet::DroneSettings s;
  s.name = "Drone1";
  return s;
}

TEST(AdapterRegistry, CreatesWithTheAdapterOfThatName) {
  AdapterRegistry registry;
  registry.register_adapter("sim", fake_factory("sim"));
  registry.register_adapter("mavlink", fake_factory("mavlink"));
  EventLoop loop;
  CreateResult r = registry.create("mavlink", settings(), fleet::generic_multirotor("Quad"), loop);
  ASSERT_EQ(r.status, CreateStatus::success) << r.message;
  EXPECT_EQ(r.drone->name(), "mavlink:Drone1");
  EXPECT_EQ(registry.names(), (std::vector<std::string>{"mavlink", "sim"}));
}

TEST(AdapterRegistry, UnknownAdapterIsAnErrorListingTheKnownOnes) {
  AdapterRegistry registry;
  registry.register_adapter("sim", fake_factory("sim"));
  EventLoop loop;
  CreateResult r = registry.create("px5", settings(), fleet::generic_multirotor("Quad"), loop);
  EXPECT_EQ(r.status, CreateStatus::unknown_adapter);
  EXPECT_EQ(r.drone, nullptr);
  EXPECT_EQ(r.message, "drone 'Drone1': no adapter named 'px5' in this program (known: sim)");
}

TEST(AdapterRegistry, AdapterClaimingSuccessWithoutADroneHasFailed) {
  AdapterRegistry registry;
  registry.register_adapter("broken", [](const fleet::DroneSettings&, const fleet::DroneType&,
                                         EventLoop&) { return CreateResult{}; });
  EventLoop loop;
  CreateResult r = registry.create("broken", settings(), fleet::generic_multirotor("Quad"), loop);
  EXPECT_EQ(r.status, CreateStatus::adapter_failed);
  EXPECT_STREQ(create_status_name(r.status), "adapter_failed");
}

TEST(AdapterRegistry, LaterRegistrationReplacesTheEarlier) {
  AdapterRegistry registry;
  registry.register_adapter("sim", fake_factory("old"));
  registry.register_adapter("sim", fake_factory("new"));
  EventLoop loop;
  CreateResult r = registry.create("sim", settings(), fleet::generic_multirotor("Quad"), loop);
  ASSERT_TRUE(r.drone);
  EXPECT_EQ(r.drone->name(), "new:Drone1");
}

}  // namespace
}  // namespace eamos::mid
