#include "assets.hpp"

#include <string_view>

namespace caldaq_assets {
extern const std::string_view page_html;
extern const std::string_view fleet_html;
extern const std::string_view strings_en;
extern const std::string_view present_js;
extern const std::string_view uplot_js;
extern const std::string_view uplot_css;
}  // namespace caldaq_assets

namespace cal::daq::web {
namespace {
void replace(std::string& s, std::string_view marker, std::string_view with) {
  if (const auto at = s.find(marker); at != std::string::npos) s.replace(at, marker.size(), with);
}
void replace_all(std::string& s, std::string_view marker, std::string_view with) {
  for (auto at = s.find(marker); at != std::string::npos; at = s.find(marker, at + with.size()))
    s.replace(at, marker.size(), with);
}

// The presentation both pages share (daq/web/present.js) and the units' signs it writes.
void present(std::string& page, std::string_view unit_signs) {
  replace(page, "/*UNIT_SIGNS*/", unit_signs);
  replace(page, "/*PRESENT_JS*/", caldaq_assets::present_js);
}
}  // namespace

std::string operator_page(std::string_view nonce, std::string_view unit_signs) {
  std::string page(caldaq_assets::page_html);
  // The page's own script elements, before anything is inserted (the nonce is base64: no
  // character of it needs escaping in an attribute).
  if (!nonce.empty())
    replace_all(page, "<script>", "<script nonce=\"" + std::string(nonce) + "\">");
  // The strings first: the chart library's code is inserted after, and is not searched.
  replace(page, "/*STRINGS*/", caldaq_assets::strings_en);
  present(page, unit_signs);
  replace(page, "/*UPLOT_CSS*/", caldaq_assets::uplot_css);
  replace(page, "/*UPLOT_JS*/", caldaq_assets::uplot_js);
  return page;
}

std::string fleet_page(std::string_view nonce, std::string_view unit_signs) {
  std::string page(caldaq_assets::fleet_html);
  if (!nonce.empty())
    replace_all(page, "<script>", "<script nonce=\"" + std::string(nonce) + "\">");
  present(page, unit_signs);
  return page;
}

}  // namespace cal::daq::web
