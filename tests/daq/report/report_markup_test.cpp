// The reports' escaping (daq/src/report/markup.cpp) and what PLplot makes of hostile text in a
// plot: a machine or customer name must not end the CSS string, <style> block, SVG text or HTML
// element it is put in (issue 27: `</style>` in a name ran a script in the report).
#include <gtest/gtest.h>

#include <regex>
#include <string>

#include "report/markup.hpp"
#include "report/plot.hpp"

namespace {

namespace r = cal::daq::report;

const std::string hostile =
    R"(</style><script>alert(1)</script>"><img src=x onerror=alert(2)>'</text></svg>&amp;\)";

TEST(ReportMarkup, CssStringEscapesAllButLettersDigitsAndSpaces) {
  EXPECT_EQ(r::css_string("Run 7 X"), "\"Run 7 X\"");
  EXPECT_EQ(r::css_string("a\"b\\c"), "\"a\\000022b\\00005Cc\"");
  EXPECT_EQ(r::css_string("</style>"), "\"\\00003C\\00002Fstyle\\00003E\"");
  EXPECT_EQ(r::css_string("a\nb"), "\"a\\00000Ab\"");
  const std::string s = r::css_string(hostile);
  // Inside the quotes only letters, digits, spaces and the escapes' backslashes.
  const std::string inner = s.substr(1, s.size() - 2);
  EXPECT_TRUE(std::regex_match(inner, std::regex(R"(([A-Za-z0-9 ]|\\[0-9A-F]{6})*)"))) << s;
}

TEST(ReportMarkup, CssStringEscapesUtf8ByCodePoint) {
  EXPECT_EQ(r::css_string("ACME — Müller"), "\"ACME \\002014\\000020M\\0000FCller\"");
  // A space after an escape would be read as its end and lost ("Run 1:Positioning").
  EXPECT_EQ(r::css_string("Run 1: X, Y"), "\"Run 1\\00003A\\000020X\\00002C\\000020Y\"");
  EXPECT_EQ(r::css_string("\xF0\x9F\x94\xA7"), "\"\\01F527\"");  // U+1F527, four bytes
  // Not UTF-8 (a stray byte, an overlong '/', a truncated sequence, NUL): U+FFFD, never the
  // byte's own character.
  EXPECT_EQ(r::css_string("\xFF"), "\"\\00FFFD\"");
  EXPECT_EQ(r::css_string("\xC0\xAF"), "\"\\00FFFD\\00FFFD\"");
  EXPECT_EQ(r::css_string("a\xE2\x80"), "\"a\\00FFFD\\00FFFD\"");
  EXPECT_EQ(r::css_string(std::string_view("\0", 1)), "\"\\00FFFD\"");
}

TEST(ReportMarkup, HtmlTextAndAttribute) {
  EXPECT_EQ(r::html_text(R"(<a href="x" title='y'>&</a>)"),
            "&lt;a href=&quot;x&quot; title=&#39;y&#39;&gt;&amp;&lt;/a&gt;");
  EXPECT_EQ(r::html_attribute("\" onmouseover='x'"), "&quot; onmouseover=&#39;x&#39;");
  EXPECT_EQ(r::html_text("Müller — 1 µm"), "Müller — 1 µm");
}

TEST(ReportMarkup, PlotTextKeepsPlplotEscapesLiteral) {
  EXPECT_EQ(r::plot_text("#<sans-serif/>#[0x222e] #u"), "##<sans-serif/>##[0x222e] ##u");
  EXPECT_EQ(r::plot_text("a\nb\tc\x7F"), "abc");
  EXPECT_EQ(r::plot_text("x̄↑ ± 2s"), "x̄↑ ± 2s");
}

TEST(ReportMarkup, ContentSecurityPolicyAllowsNoScriptNoFramesNoFetches) {
  const std::string meta = r::csp_meta();
  EXPECT_TRUE(meta.starts_with("<meta http-equiv=\"Content-Security-Policy\" content=\""));
  for (const char* directive :
       {"default-src 'none'", "script-src 'none'", "frame-src 'none'", "object-src 'none'",
        "img-src data:", "base-uri 'none'", "form-action 'none'"})
    EXPECT_NE(meta.find(directive), std::string::npos) << directive;
}

// The texts of an SVG as a browser reads them: the content of <tspan> elements with the
// character references decoded (PLplot writes them as &#x...;).
std::string decoded_texts(const std::string& svg) {
  std::string out;
  static const std::regex tspan(R"(<tspan[^>]*>([^<]*)</tspan>)");
  static const std::regex ref(R"(&#x([0-9a-fA-F]+);|&lt;|&gt;|&amp;|&quot;|&#39;)");
  for (std::sregex_iterator it(svg.begin(), svg.end(), tspan), end; it != end; ++it) {
    const std::string t = (*it)[1].str();
    std::size_t last = 0;
    for (std::sregex_iterator m(t.begin(), t.end(), ref), mend; m != mend; ++m) {
      out += t.substr(last, static_cast<std::size_t>(m->position()) - last);
      const std::string e = (*m)[0].str();
      if (e == "&lt;")
        out += '<';
      else if (e == "&gt;")
        out += '>';
      else if (e == "&amp;")
        out += '&';
      else if (e == "&quot;")
        out += '"';
      else if (e == "&#39;")
        out += '\'';
      else {
        const auto cp = static_cast<char32_t>(std::stoul((*m)[1].str(), nullptr, 16));
        if (cp < 0x80) {
          out += static_cast<char>(cp);
        } else {
          out += '?';  // this test's hostile text is ASCII
        }
      }
      last = static_cast<std::size_t>(m->position() + m->length());
    }
    out += t.substr(last);
  }
  return out;
}

// Every text of a chart comes from data somewhere (an instrument's name in a legend, a run's
// date on an axis): the SVG has no element or attribute made of it, and shows it verbatim.
TEST(ReportMarkup, HostileTextInAPlotIsText) {
  r::XyChart chart{.title = hostile, .x_label = hostile, .y_label = "#<sans-serif/>y"};
  chart.lines.push_back({.x = {0, 1, 2}, .y = {0, 1, 0}, .label = hostile + " legend"});
  const std::string svg = r::svg(chart);
  for (const char* tag : {"<script", "<img", "</style", "<style", "</svg><"})
    EXPECT_EQ(svg.find(tag), std::string::npos) << tag;
  // One <svg> element, ended by its own end tag.
  EXPECT_EQ(svg.find("</svg>"), svg.rfind("</svg>"));
  EXPECT_EQ(svg.find_first_not_of(" \n", svg.rfind("</svg>") + 6), std::string::npos);
  // PLplot writes every character of a text as a character reference (&#x3c; for <): the
  // hostile text is in the SVG only there and, escaped, in the accessible name.
  EXPECT_EQ(svg.find("onerror"), svg.rfind("onerror"));
  const std::string texts = decoded_texts(svg);
  EXPECT_NE(texts.find(hostile), std::string::npos) << texts;
  EXPECT_NE(texts.find(hostile + " legend"), std::string::npos) << texts;
  EXPECT_NE(texts.find("#<sans-serif/>y"), std::string::npos) << texts;  // not a font change
  // The accessible name is an attribute: its quotes escaped.
  EXPECT_NE(svg.find("aria-label=\"&lt;/style&gt;&lt;script&gt;"), std::string::npos);
}

TEST(ReportMarkup, HostileTextInAPolarPlotIsText) {
  r::PolarChart chart{.title = hostile, .first_axis = "<b>", .second_axis = "&"};
  chart.centre_text = hostile;
  chart.traces.push_back({.x = {0, 90, 180, 270}, .y = {1, -1, 1, -1}, .label = hostile});
  const std::string svg = r::svg(chart);
  EXPECT_EQ(svg.find("<script"), std::string::npos);
  EXPECT_EQ(svg.find("<b>"), std::string::npos);
  const std::string texts = decoded_texts(svg);
  EXPECT_NE(texts.find(hostile), std::string::npos) << texts;
  EXPECT_NE(texts.find("+<b>"), std::string::npos) << texts;
}

}  // namespace
