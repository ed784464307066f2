#include "report_html.hpp"

#include <cstdio>
#include <stdexcept>

namespace cli::html {

std::string escape(const std::string& text) {
    std::string out;
    out.reserve(text.size());
    for (char c : text) switch (c) {
            case '&': out += "&amp;"; break;
            case '<': out += "&lt;"; break;
            case '>': out += "&gt;"; break;
            case '"': out += "&quot;"; break;
            case '\'': out += "&#39;"; break;
            default: out += c;
        }
    return out;
}

std::string png_image(const std::string& png, const std::string& alt) {
    return "<img src=\"data:image/png;base64," + base64(png) + "\" alt=\"" + escape(alt) + "\">";
}

std::string number(const nlohmann::json& data, const std::string& pointer, int digits) {
    const nlohmann::json& x = data.at(nlohmann::json::json_pointer(pointer));
    const std::string open = "<span class=\"num\" data-json=\"" + escape(pointer) + "\"";
    if (x.is_null()) return open + ">n/a</span>";
    if (x.is_number_integer()) return open + ">" + x.dump() + "</span>";
    if (!x.is_number()) throw std::logic_error("report: " + pointer + " is not a number");
    char buf[64];
    std::snprintf(buf, sizeof buf, "%.*g", digits, x.get<double>());
    return open + " data-digits=\"" + std::to_string(digits) + "\">" + buf + "</span>";
}

std::string page(const std::string& title, const std::string& body) {
    return "<!DOCTYPE html>\n<html lang=\"en\">\n<head>\n<meta charset=\"utf-8\">\n<title>" + escape(title) +
           "</title>\n<style>\n"
           "body{font-family:sans-serif;max-width:1120px;margin:1.5em auto;padding:0 1em;color:#212121;"
           "background:#fff;line-height:1.4}\n"
           "h1{font-size:1.6em;margin-bottom:.2em}h2{border-bottom:2px solid #1f5fa8;padding-bottom:.15em;"
           "margin-top:1.6em}\n"
           "table{border-collapse:collapse;margin:.6em 0}td,th{border:1px solid #ccc;padding:.25em .6em;"
           "text-align:right}th{background:#eef3f9}td.l,th.l{text-align:left}\n"
           "img{max-width:100%;height:auto;border:1px solid #ddd}.pair{display:flex;gap:1em;flex-wrap:wrap}"
           ".pair figure,.pair>section{flex:1 1 520px;margin:0;min-width:0}figcaption{font-size:.9em;color:#555}\n"
           ".note{color:#555;font-size:.92em}.big{font-size:1.25em;font-weight:bold}\n"
           ".view3d{width:100%;height:440px;border:1px solid #ddd}h3{margin:.2em 0;font-size:1.05em}"
           ".half{max-width:calc(50% - .5em)}.switch button{margin:0 .4em .4em 0;padding:.3em .7em;"
           "border:1px solid #1f5fa8;background:#fff;border-radius:3px;cursor:pointer}.switch button.on{background:#1f5fa8;"
           "color:#fff}svg{width:100%;height:auto;border:1px solid #ddd;background:#fff}\n"
           ".bar{display:inline-block;width:140px;height:.9em;vertical-align:middle;background:linear-gradient(to right,"
           "rgb(0,0,255) 28.57%,rgb(255,0,0) 71.43%)}.undefined{display:inline-block;width:1.4em;height:.9em;"
           "vertical-align:middle;background:rgb(128,128,128)}\n"
           "#tip{position:absolute;background:#fffbe6;border:1px solid #aa8;padding:.2em .5em;font-size:.85em;"
           "pointer-events:none;white-space:nowrap}\n"
           "</style>\n</head>\n<body>\n" +
           body + "</body>\n</html>\n";
}

}  // namespace cli::html
