// The interactive part of `clfractal report`: LD-coloured meshes made small enough to inline
// (vertex clustering, quantised arrays), three.js from Debian's libjs-three read when the page
// is written, and the section that turns the surface, switches isovalues and plots the curves.
#pragma once
#include <nlohmann/json.hpp>

#include <array>
#include <future>
#include <optional>
#include <string>
#include <vector>

#include "clfractal/mesh.hpp"

namespace cli::explore {

/// Most triangles one inlined mesh may have.
constexpr std::size_t max_triangles = 300000;

/// A mesh for the browser, little-endian binary arrays: positions as uint16 triples quantised
/// over the bounding box [lo, hi], colours as uint8 RGB (the thesis colour map of the mean LD
/// of each cluster, grey where undefined), triangles as uint16 (up to 65535 vertices) or
/// uint32 indices.
struct WebMesh {
    std::size_t triangles_full = 0;  ///< triangles of the marching-cubes mesh
    std::size_t triangles = 0, vertices = 0;
    double cell = 0;  ///< clustering cell edge, physical units (0: the mesh as extracted)
    std::array<double, 3> lo{}, hi{};
    std::string positions, colours, indices;
    bool wide_indices = false;
};

/// `mesh` (with mesh.ld set) as a WebMesh of at most `triangles` triangles: the mesh itself
/// when it is that small, else vertices merged on a cubic grid (one vertex per occupied cell at
/// the mean position, triangles that keep three distinct cells, each once), the cell grown
/// until it fits. Throws std::invalid_argument for triangles < 1 or > max_triangles.
WebMesh web_mesh(const clfractal::Mesh& mesh, std::size_t triangles);

/// three.js and its OrbitControls, as Debian's libjs-three installs them.
struct Three {
    std::string dir, js;
};

/// three.min.js and examples/js/controls/OrbitControls.js from $CLFRACTAL_THREE_DIR, else
/// /usr/share/javascript/three; nullopt with `why` set when either is missing or cannot be
/// inlined in a <script> element.
std::optional<Three> load_three(std::string& why);

/// One precomputed isovalue of the switch.
struct Choice {
    std::string role, text;  ///< "recommended (clean)", ...; the isovalue as the page writes it
    double isovalue = 0;
    std::size_t slice_z = 0;
    WebMesh mesh;
    std::shared_future<std::string> slice_png;  ///< drawn while the report goes on
};

/// The JSON facts of a choice (report --json "explore" entries).
nlohmann::json facts(const Choice& c);

/// What the curves of the section plot, from the report's JSON, in columns: per isovalue D
/// (6 significant digits), the count I(s), components, verdict (an index into "verdicts") and
/// r(s) (4 digits, null where not estimated); the clean limit, the clean bands as [first,
/// last], the recommended and the noisiest isovalues.
nlohmann::json plot_data(const nlohmann::json& report);

/// The section (hidden until its script runs), the curves' data and the meshes inline,
/// three.js and the script that draws the 3D view, the slice and the SVG curves.
std::string section(const nlohmann::json& report, const std::vector<Choice>& choices, const Three& three);

}  // namespace cli::explore
