// Building blocks of the self-contained HTML report (clfractal report): escaping, numbers
// tied to the report's JSON, and images inline as data: URIs.
#pragma once
#include <nlohmann/json.hpp>

#include <string>

#include "base64.hpp"

namespace cli::html {

/// Text with &, <, >, " and ' escaped.
std::string escape(const std::string& text);

/// An <img> whose source is the PNG itself (data:image/png;base64,...).
std::string png_image(const std::string& png, const std::string& alt);

/// The number at JSON pointer `pointer` of `data`, as a <span data-json="pointer"> holding
/// it exactly (integers) or with `digits` significant digits (printf %.*g, then
/// data-digits="digits"), or "n/a" for null: every number of the page can be checked
/// against the JSON. Throws std::logic_error for a missing or non-numeric entry.
std::string number(const nlohmann::json& data, const std::string& pointer, int digits = 5);

/// A whole page: title, inline style sheet, body.
std::string page(const std::string& title, const std::string& body);

}  // namespace cli::html
