// Golden files of Listing 2's graphs. Regenerate after an intended change with
//   EAMOS_UPDATE_GOLDEN=1 ctest -R Golden
// and review the diff like code.
#include <cstdlib>
#include <fstream>
#include <sstream>

#include "deploy/synthesize.h"
#include "helpers.h"

namespace eamos {
namespace {

std::string read_file(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  std::ostringstream s;
  s << in.rdbuf();
  return s.str();
}

void expect_golden(const std::string& name, const std::string& actual) {
  std::string path = std::string(EAMOS_TEST_DATA) + "/golden/listing2/" + name;
  if (std::getenv("EAMOS_UPDATE_GOLDEN")) {
    std::ofstream(path, std::ios::binary) << actual;
    return;
  }
  std::string expected = read_file(path);
  ASSERT_FALSE(expected.empty()) << path << " missing; run with EAMOS_UPDATE_GOLDEN=1";
  EXPECT_EQ(expected, actual) << "output differs from " << path;
}

class Golden : public ::testing::Test {
 protected:
  void SetUp() override {
    Diagnostics diags;
    ASSERT_TRUE(graph::compile_file(std::string(EAMOS_SOURCE_DIR) + "/examples/listing2.eamos", "",
                                    diags, c_))
        << diags.format();
    // Paths in outputs are relative, so the goldens do not depend on the checkout folder.
    c_.source->path = "examples/listing2.eamos";
  }
  graph::Compilation c_;
};

TEST_F(Golden, Listing2Amt) {
  expect_golden("amt.dot", graph::amt_dot(c_));
  expect_golden("amt.json", graph::amt_json(c_).dump(1) + "\n");
}

TEST_F(Golden, Listing2Meg) {
  expect_golden("meg.dot", graph::meg_dot(c_));
  expect_golden("meg.json", graph::meg_json(c_).dump(1) + "\n");
}

TEST_F(Golden, Listing2MdgPerDrone) {
  for (int d = 0; d < c_.drone_count(); ++d) {
    expect_golden("mdg-" + c_.drone_name(d) + ".dot", graph::mdg_dot(c_, d));
    expect_golden("mdg-" + c_.drone_name(d) + ".json", graph::mdg_json(c_, d).dump(1) + "\n");
  }
}

TEST_F(Golden, Listing2Stats) { expect_golden("stats.json", graph::stats_json(c_).dump(2) + "\n"); }

}  // namespace
}  // namespace eamos
