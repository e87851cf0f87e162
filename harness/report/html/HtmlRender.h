// The HTML renderer of the report model (harness/report/ReportModel.h): one
// self-contained page, its style inline, no script, no external reference
// (no http:, https: or file: URL; images are data: URIs, plots inline SVG),
// so that it opens from file:// without a server or a network.
#pragma once

#include <string>
#include <string_view>

#include "harness/report/ReportModel.h"

namespace cb::html {

// The whole page: a title, a table of contents, then each section as
// <section id="s-N"><h2>. Tables are <table class="report"> with a
// data-table attribute naming their section; a text cell that is a status
// word (pass, fail, skipped, ok, failed, crashed, timed out, out of memory,
// unavailable, unsupported) gets class "st-<word>" (spaces as '-'). An Image
// with data is embedded as a data:image/png URI; without, only its caption and
// path are shown. A Link is shown as text unless its target is a fragment
// ("#...") in the page.
std::string RenderHtml(const report::Report& report);

// RFC 4648 base64 with padding.
std::string Base64(std::string_view bytes);

}  // namespace cb::html
