// clfractal survey: thesis Table 2.1 over a set of volumes (docs/definitions.md §11 "Survey
// row", §20 "Correlation"): per volume and per category the average fractal box dimension, its
// spread, the subsampled grid's average, |full - subsampled|, and the correlation of D
// with the number of isosurface components; a histogram of per-volume averages (Fig. 2.2).
#include <algorithm>
#include <chrono>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <iomanip>
#include <iostream>
#include <map>
#include <memory>
#include <sstream>

#include "clfractal/components.hpp"
#include "clfractal/fd.hpp"
#include "cli.hpp"
#include "output.hpp"

using namespace clfractal;
namespace fs = std::filesystem;

namespace cli {

namespace {

struct SurveyArgs {
    std::string input, markdown, csv, histogram;
};

struct Entry {
    std::string path, name, category;
    RawOptions raw;
};

std::vector<std::string> split(const std::string& line, char sep) {
    std::vector<std::string> out;
    std::string cell;
    std::istringstream in(line);
    while (std::getline(in, cell, sep)) out.push_back(cell);
    if (!line.empty() && line.back() == sep) out.push_back("");
    return out;
}

std::vector<Entry> read_manifest(const std::string& path) {
    std::error_code ec;
    // A FIFO would block, a device never end.
    if (!fs::is_regular_file(path, ec))
        throw InputError(path + ": not a regular file (survey reads a manifest file or a directory)");
    std::ifstream in(path);
    if (!in) throw InputError(path + ": cannot read the manifest");
    std::string line;
    if (!std::getline(in, line)) throw InputError(path + ": empty manifest");
    const auto header = split(line, '\t');
    auto column = [&](const std::string& name) {
        auto it = std::find(header.begin(), header.end(), name);
        if (it == header.end()) throw InputError(path + ": the manifest has no column '" + name + "'");
        return std::size_t(it - header.begin());
    };
    const std::size_t c_file = column("file"), c_name = column("name"), c_dims = column("dims"),
                      c_type = column("dtype"), c_cat = column("category");
    std::vector<Entry> out;
    int row = 1;
    while (std::getline(in, line)) {
        ++row;
        if (!line.empty() && line.back() == '\r') line.pop_back();
        if (line.empty() || line[0] == '#') continue;
        const auto cells = split(line, '\t');
        const std::string where = path + " row " + std::to_string(row);
        if (cells.size() < header.size()) throw InputError(where + ": expected " + std::to_string(header.size()) + " columns");
        Entry e;
        e.path = (fs::path(path).parent_path() / cells[c_file]).string();
        e.name = cells[c_name];
        e.category = cells[c_cat];
        std::istringstream d(cells[c_dims]);
        long long x = 0, y = 0, z = 0;
        char a = 0, b = 0;
        if (!(d >> x >> a >> y >> b >> z) || a != 'x' || b != 'x' || x < 1 || y < 1 || z < 1)
            throw InputError(where + ": dims '" + cells[c_dims] + "': expected XxYxZ");
        e.raw.dims = Dims{std::size_t(x), std::size_t(y), std::size_t(z)};
        try {
            e.raw.type = parse_value_type(cells[c_type]);
        } catch (const InputError& err) {
            throw InputError(where + ": dtype: " + err.what());
        }
        out.push_back(e);
    }
    if (out.empty()) throw InputError(path + ": the manifest lists no volumes");
    return out;
}

std::vector<Entry> read_input(const std::string& input) {
    if (!fs::exists(input)) throw InputError(input + ": no such file or directory");
    if (!fs::is_directory(input)) return read_manifest(input);
    if (fs::exists(fs::path(input) / "MANIFEST.tsv")) return read_manifest((fs::path(input) / "MANIFEST.tsv").string());
    std::vector<Entry> out;
    for (auto& f : fs::directory_iterator(input)) {
        const std::string ext = f.path().extension().string();
        Dims d;
        ValueType t;
        if (ext == ".nrrd" || ext == ".nhdr" || (ext == ".raw" && parse_raw_name(f.path().string(), d, t)))
            out.push_back({f.path().string(), f.path().stem().string(), "uncategorized", {}});
    }
    std::sort(out.begin(), out.end(), [](const Entry& a, const Entry& b) { return a.path < b.path; });
    if (out.empty()) throw InputError(input + ": no NAME_XxYxZ_TYPE.raw or NRRD files and no MANIFEST.tsv");
    return out;
}

struct Row {
    std::string name, category, dims, type;
    std::size_t isovalues = 0, defined = 0;
    double mean = NAN, std = NAN, mean_sub = NAN, full_sub = NAN, corr = NAN, corr_area = NAN;
    std::size_t corr_used = 0;
    double seconds = 0;
};

Row survey_one(Context& ctx, const Entry& e) {
    Volume v = read_volume(e.path, e.raw);
    Row r;
    r.name = e.name;
    r.category = e.category;
    r.dims = dims_string(v.dims());
    r.type = value_type_name(v.type());
    const auto t0 = std::chrono::steady_clock::now();
    IsovalueSet iso = IsovalueSet::for_volume(v, 256);
    r.isovalues = iso.size();
    // Levels 0, 1, 2: D_full from G/G', D_sub from G'/G''; E at level 0 for the correlation.
    // The volume on the device once, for the spans and the components.
    const ReportVolume input(ctx, v);
    const SpanOptions opt{{SpanKind::cubes, SpanKind::edges}, 3, 0};
    SpanResult spans = input.device() ? count_spans(*input.device(), iso, opt) : count_spans(ctx, v, iso, opt);
    const auto& I = spans.get(SpanKind::cubes).counts;
    const auto& E = spans.get(SpanKind::edges).counts;
    const std::size_t K = iso.size();
    std::vector<double> full(K), sub(K);
    for (std::size_t j = 0; j < K; ++j) {
        full[j] = I[0][j] && I[1][j] ? std::log2(double(I[0][j]) / double(I[1][j])) : NAN;
        sub[j] = I[1][j] && I[2][j] ? std::log2(double(I[1][j]) / double(I[2][j])) : NAN;
    }
    FdSummary s = summarize(full, I[0], I[1]);
    r.defined = s.defined;
    r.mean = s.mean;
    r.std = s.std;
    double sum_sub = 0, sum_diff = 0;
    std::size_t n_sub = 0, n_diff = 0;
    for (std::size_t j = 0; j < K; ++j) {
        if (std::isnan(sub[j])) continue;
        sum_sub += sub[j];
        ++n_sub;
        if (!std::isnan(full[j])) {
            sum_diff += std::abs(full[j] - sub[j]);
            ++n_diff;
        }
    }
    r.mean_sub = n_sub ? sum_sub / double(n_sub) : NAN;
    r.full_sub = n_diff ? sum_diff / double(n_diff) : NAN;
    ComponentCurve c = input.device() ? count_components(*input.device(), iso, Connectivity::cube)
                                      : count_components(ctx, v, iso, Connectivity::cube);
    ComponentCorrelation cc = correlate_components(ctx, full, E[0], c.components, v.dims());
    r.corr = cc.components;
    r.corr_area = cc.components_per_area;
    r.corr_used = cc.used;
    r.seconds = seconds_since(t0);
    return r;
}

// Mean and population standard deviation of the defined values.
std::pair<double, double> mean_std(const std::vector<double>& x) {
    double sum = 0;
    std::size_t n = 0;
    for (double a : x)
        if (!std::isnan(a)) sum += a, ++n;
    if (!n) return {NAN, NAN};
    const double m = sum / double(n);
    double var = 0;
    for (double a : x)
        if (!std::isnan(a)) var += (a - m) * (a - m);
    return {m, std::sqrt(var / double(n))};
}

std::string num(double x, int precision = 2) {
    if (std::isnan(x)) return "n/a";
    std::ostringstream o;
    o << std::fixed << std::setprecision(precision) << x;
    return o.str();
}

struct Summary {
    std::string category;
    std::size_t n = 0, n_corr = 0;
    double mean, std, avg_std, mean_sub, full_sub, corr, corr_std, corr_area, corr_area_std, kappa;
};

// Thesis §3.1: data sets whose D hardly varies (std < 0.05, "very simple synthetic data
// sets with fractal dimension very close to two regardless of isovalue") are left out of
// the correlation statistics: a correlation with an almost constant curve is noise.
constexpr double flat_fd_std = 0.05;
bool flat(const Row& r) { return !(r.std >= flat_fd_std); }

Summary summarize_rows(const std::string& category, const std::vector<const Row*>& rows) {
    std::vector<double> mean, stdv, sub, diff, corr, corr_area;
    for (const Row* r : rows) {
        mean.push_back(r->mean);
        stdv.push_back(r->std);
        sub.push_back(r->mean_sub);
        diff.push_back(r->full_sub);
        corr.push_back(flat(*r) ? NAN : r->corr);
        corr_area.push_back(flat(*r) ? NAN : r->corr_area);
    }
    Summary s;
    s.category = category;
    s.n = rows.size();
    std::tie(s.mean, s.std) = mean_std(mean);
    s.avg_std = mean_std(stdv).first;
    s.mean_sub = mean_std(sub).first;
    s.full_sub = mean_std(diff).first;
    std::tie(s.corr, s.corr_std) = mean_std(corr);
    std::tie(s.corr_area, s.corr_area_std) = mean_std(corr_area);
    s.kappa = s.mean / 3;
    for (const Row* r : rows) s.n_corr += !flat(*r) && !std::isnan(r->corr_area);
    return s;
}

void write_histogram(const std::vector<Row>& rows, const std::string& path) {
    std::ostringstream data;
    for (const Row& r : rows)
        if (!std::isnan(r.mean)) data << r.mean << "\n";
    std::ostringstream script;
    script << "set terminal pngcairo size 800,480 font 'sans,11'\n"
           << "set xlabel 'average fractal box dimension of a data set'\nset ylabel 'data sets'\n"
           << "set title 'Histogram of average fractal dimensions (" << rows.size() << " data sets)'\n"
           << "set key off\nset ytics 1\nset grid ytics\nset style fill solid 0.6 border -1\nset boxwidth 0.045\n"
           << "set xrange [1.9:3.0]\nset yrange [0:*]\nset xtics 0.1\nbin(x) = 0.05 * floor(x / 0.05) + 0.025\n"
           << "plot '$DATA' using (bin($1)):(1.0) smooth frequency with boxes lc rgb '#1f5fa8'\n";
    plot_png(script.str(), data.str(), path);
}

// "all", then each category (medical, measured, synthetic first) that has a row.
std::vector<Summary> category_summaries(const std::vector<Row>& rows) {
    std::vector<std::string> categories;
    for (const char* c : {"medical", "measured", "synthetic"}) categories.push_back(c);
    for (const Row& r : rows)
        if (std::find(categories.begin(), categories.end(), r.category) == categories.end())
            categories.push_back(r.category);
    std::vector<Summary> sums;
    std::vector<const Row*> all;
    for (const Row& r : rows) all.push_back(&r);
    sums.push_back(summarize_rows("all", all));
    for (const auto& c : categories) {
        std::vector<const Row*> in;
        for (const Row& r : rows)
            if (r.category == c) in.push_back(&r);
        if (!in.empty()) sums.push_back(summarize_rows(c, in));
    }
    return sums;
}

// The per-volume and per-category tables as Markdown.
std::string survey_markdown(const std::vector<Row>& rows, const std::vector<Summary>& sums) {
    std::ostringstream md;
    md << "| data set | category | dims | type | FD avg | FD std | FD sub avg | avg abs(full - sub) | corr D~comp "
          "| corr D~comp/E | isovalues used |\n"
       << "|---|---|---|---|---|---|---|---|---|---|---|\n";
    for (const Row& r : rows)
        md << "| " << r.name << " | " << r.category << " | " << r.dims << " | " << r.type << " | " << num(r.mean, 3)
           << " | " << num(r.std, 3) << " | " << num(r.mean_sub, 3) << " | " << num(r.full_sub, 3) << " | "
           << num(r.corr, 2) << (flat(r) ? "*" : "") << " | " << num(r.corr_area, 2) << (flat(r) ? "*" : "") << " | "
           << r.corr_used << " |\n";
    md << "\n\\* FD std < " << flat_fd_std << ": left out of the correlation statistics (thesis §3.1).\n"
       << "\n| type | num | FD avg | FD std | avg std | avg subsampled | avg abs(full - sub) | corr num | corr avg | "
          "corr std | corr/E avg | corr/E std | growth kappa |\n"
       << "|---|---|---|---|---|---|---|---|---|---|---|---|---|\n";
    for (const Summary& s : sums)
        md << "| " << s.category << " | " << s.n << " | " << num(s.mean) << " | " << num(s.std) << " | "
           << num(s.avg_std) << " | " << num(s.mean_sub) << " | " << num(s.full_sub) << " | " << s.n_corr << " | "
           << num(s.corr) << " | "
           << num(s.corr_std) << " | " << num(s.corr_area) << " | " << num(s.corr_area_std) << " | "
           << num(s.kappa) << " |\n";
    return md.str();
}

// One CSV row per volume.
std::string survey_csv(const std::vector<Row>& rows) {
    std::ostringstream out;
    out << "name,category,dims,type,isovalues,defined,fd_mean,fd_std,fd_sub_mean,full_sub_abs,corr_components,"
           "corr_components_per_area,corr_isovalues,seconds\n";
    for (const Row& r : rows)
        out << r.name << "," << r.category << "," << r.dims << "," << r.type << "," << r.isovalues << ","
            << r.defined << "," << fd_string(r.mean) << "," << fd_string(r.std) << "," << fd_string(r.mean_sub)
            << "," << fd_string(r.full_sub) << "," << fd_string(r.corr) << "," << fd_string(r.corr_area) << ","
            << r.corr_used << "," << r.seconds << "\n";
    return out.str();
}

int run_survey(const SurveyArgs& a) {
    const std::vector<Entry> entries = read_input(a.input);
    Context& ctx = Context::shared();
    progress("survey of " + std::to_string(entries.size()) + " volumes on " + ctx.description());
    std::vector<Row> rows;
    for (std::size_t i = 0; i < entries.size(); ++i) {
        rows.push_back(survey_one(ctx, entries[i]));
        const Row& r = rows.back();
        progress("[" + std::to_string(i + 1) + "/" + std::to_string(entries.size()) + "] " + r.name + " " + r.dims + " " +
                 r.type + ": FD " + num(r.mean, 3) + ", corr " + num(r.corr, 2) + ", corr/E " + num(r.corr_area, 2) + " (" + num(r.seconds, 1) + " s)");
    }
    const std::vector<Summary> sums = category_summaries(rows);

    // Per volume and per category, as text on stdout and as Markdown.
    std::cout << std::left << std::setw(22) << "data set" << std::setw(11) << "category" << std::setw(8) << "FD avg"
              << std::setw(8) << "FD std" << std::setw(8) << "sub avg" << std::setw(10) << "|full-sub|" << std::setw(8)
              << "corr" << std::setw(8) << "corr/E" << "\n";
    for (const Row& r : rows)
        std::cout << std::setw(22) << r.name << std::setw(11) << r.category << std::setw(8) << num(r.mean, 3)
                  << std::setw(8) << num(r.std, 3) << std::setw(8) << num(r.mean_sub, 3) << std::setw(10)
                  << num(r.full_sub, 3) << std::setw(8) << num(r.corr) << std::setw(8) << num(r.corr_area)
                  << (flat(r) ? "  (flat: not in the correlation statistics)" : "") << "\n";
    std::cout << "\n"
              << std::setw(14) << "type" << std::setw(5) << "num" << std::setw(7) << "avg" << std::setw(7) << "std"
              << std::setw(9) << "avg std" << std::setw(8) << "sub" << std::setw(11) << "|full-sub|" << std::setw(7)
              << "corr" << std::setw(9) << "corr sd" << std::setw(8) << "corr/E" << std::setw(10) << "corr/E sd"
              << "kappa\n";
    for (const Summary& s : sums)
        std::cout << std::setw(14) << s.category << std::setw(5) << s.n << std::setw(7) << num(s.mean) << std::setw(7)
                  << num(s.std) << std::setw(9) << num(s.avg_std) << std::setw(8) << num(s.mean_sub) << std::setw(11)
                  << num(s.full_sub) << std::setw(7) << num(s.corr) << std::setw(9) << num(s.corr_std) << std::setw(8)
                  << num(s.corr_area) << std::setw(10) << num(s.corr_area_std) << num(s.kappa) << "\n";
    std::cout << std::right
              << "(FD: fractal box span dimension eq. 2.5, mean over the isovalues where it is defined; sub: the same\n"
                 " for G' against G''; corr: Pearson of D with the component count (cube connectivity), corr/E: with\n"
                 " components per intersected edge, over isovalues with E >= (two smallest dims product) / 4; data\n"
                 " sets with FD std < 0.05 are left out of the correlation averages, as in thesis §3.1)\n";

    if (!a.markdown.empty()) write_file_atomic(a.markdown, survey_markdown(rows, sums));
    if (!a.csv.empty()) write_file_atomic(a.csv, survey_csv(rows));
    if (!a.histogram.empty()) write_histogram(rows, a.histogram);
    return 0;
}

void setup_survey(CLI::App* c, SurveyArgs& a) {
    c->add_option("INPUT", a.input,
                  "MANIFEST.tsv (columns file, name, dims, dtype, category) or a directory of NAME_XxYxZ_TYPE.raw / "
                  "NRRD files")
        ->required();
    c->add_option("--markdown", a.markdown, "write the per-volume and per-category tables as Markdown");
    c->add_option("--csv", a.csv, "write one row per volume");
    c->add_option("--histogram", a.histogram, "draw the histogram of per-volume average FD (Fig. 2.2) to a PNG");
}

}  // namespace

Command survey_command() {
    return command<SurveyArgs>("survey", "thesis Table 2.1 over a manifest or a directory of volumes", setup_survey,
                               run_survey);
}

}  // namespace cli
