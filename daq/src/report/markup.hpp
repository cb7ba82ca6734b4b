#pragma once
// Text from outside (runs, configurations, instruments, imported files, notes, campaign and file
// names) escaped for the exact place a report puts it: one function per context, so that no
// value can end the element, attribute, string or style block it sits in (docs/reports.md,
// "Reports are inert documents"). Markup written by the report code itself is not passed
// through these; every value from outside is.
#include <string>
#include <string_view>

namespace cal::daq::report {

// HTML element content (also SVG/XML text): & < > " ' as character references.
std::string html_text(std::string_view s);
// A double-quoted HTML or SVG attribute value: as html_text (the quotes are what matters).
std::string html_attribute(std::string_view s);
// A quoted CSS string ("..."): every character but ASCII letters, digits and space as a
// six-digit hex escape (\0000HH), so no quote, backslash, newline, `<`, `>` or `/` can end the
// string or the <style> block; UTF-8 is escaped by code point (an invalid byte gives U+FFFD); a
// space right after an escape is escaped too (CSS would read it as the escape's end).
std::string css_string(std::string_view s);
// Text handed to PLplot, which reads `#` as its escape character (`#<...>` changes the font,
// `#[0x...]` is a code point): `#` doubled (PLplot's literal `#`), control characters dropped.
std::string plot_text(std::string_view s);

// The Content-Security-Policy every report carries: no script, frames, objects, forms, base
// URL or fetches; only its own inline styles and data: images and fonts. It is the first
// element of <head>, before any data, so it holds even for a file opened from disk (and for
// Chromium printing it to PDF, which then cannot pull a local file into the page).
inline constexpr std::string_view content_security_policy =
    "default-src 'none'; style-src 'unsafe-inline'; img-src data:; font-src data:; "
    "frame-src 'none'; script-src 'none'; object-src 'none'; base-uri 'none'; "
    "form-action 'none'";
// `<meta http-equiv="Content-Security-Policy" content="...">`
std::string csp_meta();

}  // namespace cal::daq::report
