// libFuzzer target: campaign files and the files `campaign status` and `collect` read back. The
// first byte picks what the rest is (docs/reliability.md, "Fuzzing"):
//   0: a campaign file (TOML) beside a two-sphere base scene `base.toml`: read and expanded (at
//      most 64 cases: the case count, not the reader, would bound the time otherwise);
//   1: the campaign.json of a planned one-case campaign, then `status` and `collect`;
//   2: the result.json of that campaign's case 0, then `collect`.
// Every file lives in a private temporary folder. An InputError is a correct answer to bad input;
// any other exception, a crash or a sanitizer report is a finding.
#include <stdlib.h>
#include <unistd.h>

#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <string>

#include "impactdeck/campaign/campaign.hpp"
#include "impactdeck/campaign/collect.hpp"
#include "impactdeck/campaign/runner.hpp"
#include "impactdeck/common/error.hpp"

namespace fs = std::filesystem;

namespace {

const char* const kBase = R"(length_unit = "mm"
[materials.steel]
youngs_modulus_Pa = 2.05e11
poisson_ratio = 0.3
density_kg_m3 = 7850
[[bodies]]
name = "left"
shape = "sphere"
radius = 50
material = "steel"
velocity_m_s = [0.5, 0, 0]
[[bodies]]
name = "right"
shape = "sphere"
radius = 50
material = "steel"
velocity_m_s = [-0.5, 0, 0]
[[impacts]]
name = "hit"
target = "right"
impactor = "left"
point = [-50, 0, 0]
restitution = 1.0
)";

void write(const fs::path& p, const std::string& text) {
  std::ofstream out(p, std::ios::binary | std::ios::trunc);
  out << text;
}

std::string read(const fs::path& p) {
  std::ifstream in(p, std::ios::binary);
  return std::string(std::istreambuf_iterator<char>(in), {});
}

struct Fixture {
  fs::path root, plan;
  std::string plan_json;
  Fixture() {
    char t[] = "/tmp/fuzz_campaign.XXXXXX";
    root = ::mkdtemp(t);
    write(root / "base.toml", kBase);
    write(root / "c.toml", "scene = \"base.toml\"\n[[cases]]\n\"impacts[0].restitution\" = 0.5\n");
    plan = root / "plan";
    impactdeck::campaign::plan_campaign(impactdeck::campaign::read_campaign(root / "c.toml"), plan);
    plan_json = read(plan / "campaign.json");
  }
};

void reset(const Fixture& f) {
  std::error_code ec;
  fs::remove_all(f.plan / "collect", ec);
  fs::remove(f.plan / "cases" / "0" / "result.json", ec);
  write(f.plan / "campaign.json", f.plan_json);
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  static const Fixture f;
  if (size < 1 || size > (1 << 18)) return 0;
  const std::string text(reinterpret_cast<const char*>(data) + 1, size - 1);
  try {
    switch (data[0] % 3) {
      case 0:
        write(f.root / "fuzz.toml", text);
        impactdeck::campaign::read_campaign(f.root / "fuzz.toml", 64);
        break;
      case 1:
        write(f.plan / "campaign.json", text);
        impactdeck::campaign::status_report(f.plan);
        impactdeck::campaign::collect(f.plan);
        break;
      default:
        write(f.plan / "cases" / "0" / "result.json", text);
        impactdeck::campaign::collect(f.plan);
        break;
    }
  } catch (const impactdeck::InputError&) {
  }
  reset(f);
  return 0;
}
