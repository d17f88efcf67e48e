#include "set_option.hpp"

namespace impactdeck::cli {

void add_set_option(CLI::App* cmd, std::vector<std::string>& into) {
  cmd->add_option("--set", into,
                  "Override a scene value before validation: KEY=VALUE, KEY a dotted path with indices, "
                  "VALUE a TOML value, e.g. --set 'bodies[1].velocity_m_s=[0,-3,0]' (repeatable)")
      ->allow_extra_args(false)
      ->type_name("KEY=VALUE");
}

std::vector<scene::Override> overrides_from(const std::vector<std::string>& texts) {
  std::vector<scene::Override> out;
  for (const auto& t : texts) out.push_back(scene::parse_override(t));
  return out;
}

}  // namespace impactdeck::cli
