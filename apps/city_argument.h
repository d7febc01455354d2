// The positional CITY of `validate` and `repair`: an existing city file of a format the city
// readers take (kCityFormatNames).
#pragma once
#include <string>

#include <CLI/CLI.hpp>

#include "options.h"

namespace lodrefine::app {

inline CLI::Option* add_city_argument(CLI::App* cmd, std::string& city) {
  return cmd->add_option("city", city, "City file (" + formats_text(kCityFormatNames) + ")")
      ->required()
      ->check(CLI::ExistingFile);
}

}  // namespace lodrefine::app
