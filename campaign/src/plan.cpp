// `campaign plan`: case folders with their resolved scenes, and campaign.json.
#include <sys/stat.h>

#include <iomanip>
#include <set>
#include <sstream>

#include <nlohmann/json.hpp>

#include "impactdeck/campaign/campaign.hpp"
#include "impactdeck/campaign/runner.hpp"
#include "impactdeck/common/error.hpp"
#include "impactdeck/common/run_transaction.hpp"
#include "impactdeck/scene/scene.hpp"
#include "detail.hpp"

namespace impactdeck::campaign {
namespace fs = std::filesystem;

std::string fnv1a64_hex(const std::string& bytes, std::uint64_t h) {
  for (unsigned char c : bytes) {
    h ^= c;
    h *= 1099511628211ull;
  }
  std::ostringstream s;
  s << std::hex << std::setw(16) << std::setfill('0') << h;
  return s.str();
}

fs::path campaign_json(const fs::path& dir) {
  if (!detail::check_inside(dir, "campaign.json", detail::Kind::file)) {
    throw InputError(dir.string(), "campaign.json", "missing: not a planned campaign folder (run 'impactdeck campaign plan')");
  }
  return dir / "campaign.json";
}

PlanResult plan_campaign(const Campaign& c, const fs::path& dir_in) {
  const fs::path dir = fs::absolute(dir_in).lexically_normal();
  // Everything the cases read: the campaign file, the base scene, its part files, each case's
  // resolved scene text. The hash says whether a folder already holds this very campaign.
  std::vector<std::string> texts;
  texts.reserve(c.cases.size());
  for (const Case& k : c.cases) texts.push_back(scene::resolved_scene_text(c.scene, k.overrides));
  std::string all = detail::read_text(c.file) + '\0' + detail::read_text(c.scene);
  std::set<fs::path> parts;
  for (const auto& b : scene::load_scene(c.scene).bodies)
    for (const auto& f : b.shape->input_files()) parts.insert(f);
  for (const auto& p : parts) all += '\0' + detail::read_text(p);
  std::vector<std::string> case_hashes;
  for (const auto& t : texts) {
    case_hashes.push_back(fnv1a64_hex(t));
    all += '\0' + case_hashes.back();
  }
  PlanResult r;
  r.cases = c.cases.size();
  r.input_hash = fnv1a64_hex(all);

  // An existing folder: the same campaign is left as it is, another refused; a `cases` entry
  // without campaign.json (not a plan of ours: never replaced, never written through) refused.
  struct stat st {};
  if (::stat(dir.c_str(), &st) == 0 && S_ISDIR(st.st_mode)) {
    if (detail::check_inside(dir, "campaign.json", detail::Kind::file)) {
      const nlohmann::json old = detail::read_json_inside(dir, "campaign.json", "campaign.json", detail::kMaxPlanBytes);
      if (!old.is_object() || old.find("input_hash") == old.end() || old["input_hash"] != r.input_hash) {
        throw InputError(dir.string(), "campaign.json",
                         "the folder holds another campaign (its input hash differs): plan into a new folder");
      }
      r.already_planned = true;
      return r;
    }
    if (detail::check_inside(dir, "cases", detail::Kind::folder)) {
      throw InputError((dir / "cases").string(), "file",
                       "exists but the folder holds no campaign.json (not a campaign plan): plan into a new folder");
    }
  }

  // One transaction: the case folders and campaign.json are staged in a hidden folder inside the
  // campaign folder and renamed into place together; a plan cut short leaves nothing.
  RunTransaction txn(dir, "--out");
  return txn.run([&] {
    const std::string where = c.file.string();
    const fs::path cases_dir = txn.folder("cases", where, "cases");
    detail::make_folder(cases_dir);
    nlohmann::json cases = nlohmann::json::array();
    for (std::size_t i = 0; i < c.cases.size(); ++i) {
      const Case& k = c.cases[i];
      const fs::path folder = cases_dir / std::to_string(k.id);
      detail::make_folder(folder);
      detail::write_new_file(folder / "scene.toml", texts[i]);
      nlohmann::json inputs = nlohmann::json::object();
      for (const auto& o : k.overrides) inputs[o.key] = o.value;
      nlohmann::json j = {{"id", k.id},
                          {"folder", fs::path("cases") / std::to_string(k.id)},
                          {"overrides", inputs},
                          {"scene_hash", case_hashes[i]},
                          {"state", "planned"}};
      if (k.point_m) j["point_m"] = {k.point_m->x(), k.point_m->y(), k.point_m->z()};
      if (!k.drop.empty()) j["drop"] = k.drop;
      if (k.orientation) {
        j["orientation_quaternion_wxyz"] = {k.orientation->w(), k.orientation->x(), k.orientation->y(),
                                            k.orientation->z()};
      }
      cases.push_back(std::move(j));
    }
    nlohmann::json doc = {{"format", "impactdeck-campaign 1"},
                          {"campaign_file", fs::absolute(c.file).lexically_normal().string()},
                          {"scene", c.scene.string()},
                          {"impact", c.impact},
                          {"generators", c.generators},
                          {"keys", c.keys},
                          {"input_hash", r.input_hash},
                          {"case_count", c.cases.size()},
                          {"slurm", detail::slurm_json(c.slurm)},
                          {"cases", cases}};
    if (!c.sequence.empty()) doc["sequence"] = c.sequence;
    if (const auto& d = c.drop_test) {
      nlohmann::json axes = nlohmann::json::array();
      for (int i = 0; i < 3; ++i) axes.push_back({d->principal_axes(0, i), d->principal_axes(1, i), d->principal_axes(2, i)});
      doc["drop_test"] = {{"standard", d->standard},
                          {"body", d->body},
                          {"mode", d->sequence.empty() ? "impact" : "sequence"},
                          {"mass_kg", d->mass_kg},
                          {"gravity_m_s2", d->gravity_m_s2},
                          {"height_m", d->height_m},
                          {"principal_axes", axes},
                          {"box_lengths_m", {d->box_lengths_m.x(), d->box_lengths_m.y(), d->box_lengths_m.z()}}};
    }
    detail::write_new_file(txn.file("campaign.json", where, "campaign.json"), doc.dump(2) + "\n");
    txn.commit();
    r.warnings = txn.warnings();
    return r;
  });
}

}  // namespace impactdeck::campaign
