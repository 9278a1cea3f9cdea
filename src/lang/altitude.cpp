#include "lang/altitude.h"

#include <cstdio>
#include <optional>
#include <string>
#include <vector>

namespace eamos::lang {
namespace {

std::string metres(double v) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%g m", v);
  return buf;
}

struct Setting {
  std::optional<SourceLocation> at;
  std::string whose;  ///< for the note: "drone 'A'" or "type 'Quad'"
};

/// Where the fleet file sets the limits' max_altitude that applies to `drone`, if it does.
Setting limit_location(const fleet::Fleet& fleet, const DroneDecl& drone) {
  if (auto o = fleet.overrides.find(drone.name); o != fleet.overrides.end() && o->second.limits.max_altitude_at)
    return {o->second.limits.max_altitude_at, "drone '" + drone.name + "'"};
  if (auto t = fleet.type_max_altitude_at.find(drone.type); t != fleet.type_max_altitude_at.end())
    return {t->second, "type '" + drone.type + "'"};
  return {};
}

class AltitudeCheck {
 public:
  AltitudeCheck(const Mission& m, const fleet::Fleet& fleet, Diagnostics& diags) : m_(m), fleet_(fleet), diags_(diags) {}

  void statement(const Statement& s) {
    if (s.kind != StatementKind::action || s.drone_index < 0) return;
    bool takeoff = s.callee == "Takeoff" && s.args.size() == 1;
    bool fly_to = s.callee == "FlyTo" && s.args.size() == 3;
    if (!takeoff && !fly_to) return;
    const Expr* arg = s.args.back();
    std::optional<double> value = literal_number(arg);
    if (!value) return;
    const DroneDecl& drone = m_.drones[s.drone_index];
    const Bounds& bounds = bounds_of(s.drone_index);
    double ground = bounds.ground;
    double z = takeoff ? ground + *value : *value;
    double ceiling = bounds.ceiling;
    if (z <= ground + 1e-9) {
      report_floor(s, arg, takeoff, *value, ground);
      return;
    }
    if (z > ground + ceiling + 1e-9) {
      std::string over = takeoff ? "takeoff altitude " + metres(*value) : "target z = " + metres(z);
      report(s, arg,
             std::string(s.drone) + "." + std::string(s.callee) + ": " + over + " is above " + std::string(s.drone) + "'s max_altitude of " +
                 metres(ceiling) + " over its home (z = " + metres(ground) + "), and the drone refuses it; " +
                 "fly at most " + metres(takeoff ? ceiling : ground + ceiling) + " or raise max_altitude in the fleet file",
             limit_location(fleet_, drone).at, "");
      return;
    }
    const fleet::Geofence* fence = bounds.fence;
    if (fence && fence->max_altitude_m && z > *fence->max_altitude_m + 1e-9)
      report(s, arg,
             std::string(s.drone) + "." + std::string(s.callee) + ": target z = " + metres(z) + " is above the geofence's max_altitude of " +
                 metres(*fence->max_altitude_m) + "; fly at most " + metres(*fence->max_altitude_m) +
                 " or raise the geofence's max_altitude in the fleet file",
             fence->max_altitude_at, "the geofence of " + std::string(s.drone) + " ends here");
  }

  int settings_made() const { return settings_made_; }

 private:
  struct Bounds {
    bool known = false;
    double ground = 0.0;   ///< home z
    double ceiling = 0.0;  ///< max_altitude over home
    const fleet::Geofence* fence = nullptr;
  };

  /// A drone's settings are made once, not per statement: making them copies its type's
  /// whole catalogue, and a show has hundreds of FlyTos per drone.
  const Bounds& bounds_of(int drone) {
    if (bounds_.size() < m_.drones.size()) bounds_.resize(m_.drones.size());
    Bounds& b = bounds_[drone];
    if (b.known) return b;
    const DroneDecl& decl = m_.drones[drone];
    fleet::DroneSettings settings = fleet_.settings_for(decl.name, decl.type, drone);
    ++settings_made_;
    b = {true, settings.home.z, settings.limits.max_altitude_m, fleet_.geofence_for(decl.name)};
    return b;
  }

  /// The drone refuses a Takeoff to a height that is not positive, and a FlyTo to a z that is
  /// not above its home's (mid::uniform_refusal): a landing is Land's job.
  void report_floor(const Statement& s, const Expr* arg, bool takeoff, double value, double ground) {
    std::string who = std::string(s.drone) + "." + std::string(s.callee) + ": ";
    if (takeoff)
      diags_.error(m_.file, arg->loc, who + "takeoff altitude " + metres(value) +
                                          " is not above the ground, and the drone refuses it; give the height "
                                          "over its home to climb to, e.g. 5");
    else
      diags_.error(m_.file, arg->loc, who + "target z = " + metres(value) + " is not above " + std::string(s.drone) +
                                          "'s home (z = " + metres(ground) +
                                          "), and the drone refuses it; fly above z = " + metres(ground) +
                                          ", or use Land to land");
  }

  void report(const Statement& s, const Expr* arg, std::string message, std::optional<SourceLocation> at,
              std::string note) {
    diags_.error(m_.file, arg->loc, std::move(message));
    if (note.empty()) {
      const DroneDecl& drone = m_.drones[s.drone_index];
      note = "max_altitude of " + limit_location(fleet_, drone).whose + ", which " + drone.name + " flies by, is set here";
    }
    if (at && fleet_.source) diags_.note(fleet_.source.get(), *at, note);
  }

  const Mission& m_;
  const fleet::Fleet& fleet_;
  Diagnostics& diags_;
  std::vector<Bounds> bounds_;
  int settings_made_ = 0;
};

}  // namespace

void check_literal_altitudes(const Mission& mission, const fleet::Fleet& fleet, Diagnostics& diags,
                             int* settings_made) {
  AltitudeCheck check(mission, fleet, diags);
  for (const Function& f : mission.functions)
    for (const Statement& s : f.body) check.statement(s);
  if (settings_made) *settings_made = check.settings_made();
}

}  // namespace eamos::lang
