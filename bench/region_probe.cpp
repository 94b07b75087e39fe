// Where on the specimen's cloth does the gap sit? For each diagnosed capture of a benchmark run, the capture is scored
// against the diagnosis's fitted bending (its best validation drape, as absorption_probe's "fitted"), and the
// residual pixels that the localisation places on the hanging cloth (the skirt and the hem, classify_point) are carried
// back to the cloth itself: each to the nearest vertex of the fitted drape as rendered, and from there to the vertex's
// place on the flat specimen. The residual is then split by how far that place lies from the specimen's free edge
// (bands of material distance), where the localisation splits it by where the drape hangs in space. An edge that
// curls lies in the outer band wherever it hangs; folds that move the outline (yield, shear) span every band.
// Reads the truth files (to print the effect's region), so it is a benchmark tool, never part of the diagnosis.
#include <CLI/CLI.hpp>
#include <algorithm>
#include <array>
#include <cmath>
#include <filesystem>
#include <fmt/format.h>
#include <iostream>
#include <limits>
#include <nlohmann/json.hpp>

#include "drapegen/diagnosis/bending_json.hpp"
#include "drapegen/diagnosis/diagnosis.hpp"
#include "drapegen/diagnosis/forward_model.hpp"
#include "drapegen/diagnosis/hem_profile.hpp"
#include "drapegen/diagnosis/localisation.hpp"
#include "drapegen/sim/blas_kernels.hpp"
#include "drapegen/sim/median.hpp"
#include "json_file.hpp"

namespace fs = std::filesystem;
using namespace drapegen;
using nlohmann::json;

namespace {

using bench::read_json;

/// Residual energy and pixels per band of material distance from the free edge, over the hanging cloth's pixels.
struct Bands {
  std::vector<double> edges;  // m: the bands' outer limits (the last band reaches the specimen's centre)
  std::vector<double> energy, pixels;
  std::vector<double> to_vertex;  // m: each pixel's distance to the nearest vertex (a check of the carrying back)
  [[nodiscard]] double enrichment(std::size_t band) const {
    double e = 0.0, p = 0.0;
    for (std::size_t b = 0; b < energy.size(); ++b) e += energy[b], p += pixels[b];
    return pixels[band] > 0.0 && e > 0.0 ? (energy[band] / e) / (pixels[band] / p) : 0.0;
  }
};

/// Material distance of each vertex from the specimen's free edge (its rest position inside the rest bounding box:
/// the specimen is a rectangle, whatever its triangulation).
std::vector<double> edge_distance(const sim::ClothMesh& mesh) {
  const Eigen::Vector2d lo = mesh.rest.rowwise().minCoeff(), hi = mesh.rest.rowwise().maxCoeff();
  std::vector<double> d(static_cast<std::size_t>(mesh.vertex_count()));
  for (int i = 0; i < mesh.vertex_count(); ++i) {
    const Eigen::Vector2d x = mesh.rest.col(i);
    d[static_cast<std::size_t>(i)] = std::min({x.x() - lo.x(), hi.x() - x.x(), x.y() - lo.y(), hi.y() - x.y()});
  }
  return d;
}

Bands bands_of(const diagnosis::ForwardModel& model, const diagnosis::ScoredDrape& drape,
               const std::vector<double>& edges) {
  Bands B;
  B.edges = edges;
  B.energy.assign(edges.size() + 1, 0.0);
  B.pixels.assign(edges.size() + 1, 0.0);
  const double R = 0.5 * model.capture().specimen.cylinder_diameter;
  const diagnosis::HemProfile outline = diagnosis::rotate(diagnosis::hem_profile_from_mesh(drape.mesh), drape.angle);
  // The drape as rendered: turned by its angle about +z (ForwardModel's render).
  const Eigen::Matrix3Xd turned =
      Eigen::AngleAxisd(drape.angle, Eigen::Vector3d::UnitZ()).toRotationMatrix() * drape.mesh.positions;
  const std::vector<double> from_edge = edge_distance(drape.mesh);
  diagnosis::for_each_residual_point(model, drape, [&](std::size_t, const Eigen::Vector3d& p, double res) {
    const diagnosis::Region r = diagnosis::classify_point(p, outline, R);
    if (r != diagnosis::Region::kSkirt && r != diagnosis::Region::kHem) return;
    Eigen::Index nearest = 0;
    const double d2 = (turned.colwise() - p).colwise().squaredNorm().minCoeff(&nearest);
    B.to_vertex.push_back(std::sqrt(d2));
    const double m = from_edge[static_cast<std::size_t>(nearest)];
    const auto band = static_cast<std::size_t>(std::upper_bound(edges.begin(), edges.end(), m) - edges.begin());
    B.energy[band] += res * res;
    B.pixels[band] += 1.0;
  });
  return B;
}

/// What the summary needs of a case: its true region, the outer band's enrichment, the report's hem over skirt.
struct Row {
  std::string truth;
  double outer_band = 0.0, hem_over_skirt = 0.0;
};

/// The chance that a case whose effect acts at the hem scores above one whose effect acts at the skirt (ties half):
/// 1 separates them, 0.5 does not.
double hem_above_skirt(const std::vector<Row>& rows, double Row::*score) {
  double wins = 0.0, pairs = 0.0;
  for (const Row& h : rows) {
    if (h.truth != "hem") continue;
    for (const Row& s : rows) {
      if (s.truth != "skirt") continue;
      pairs += 1.0;
      wins += h.*score > s.*score ? 1.0 : h.*score == s.*score ? 0.5 : 0.0;
    }
  }
  return pairs > 0.0 ? wins / pairs : std::numeric_limits<double>::quiet_NaN();
}

sim::Status probe_case(const fs::path& run, const std::string& name, const diagnosis::DiagnosisSettings& settings,
                       const std::vector<sim::InitialStateSpec>& states, const std::vector<double>& edges,
                       std::vector<Row>& rows) {
  const auto truth = read_json(run / "truth" / (name + ".json"));
  if (!truth) return truth.error();
  const auto report = read_json(run / "diagnoses" / (name + ".json"));
  if (!report) return report.error();
  auto capture = diagnosis::read_capture((run / "captures" / name).string());
  if (!capture) return capture.error();
  auto model = diagnosis::ForwardModel::create(*capture, settings.fit);
  if (!model) return model.error();
  diagnosis::ModelSetup setup;
  auto fitted = diagnosis::bending_from_json(report->at("baseline").at("fitted"), "report baseline.fitted");
  if (!fitted) return fitted.error();
  setup.bending = *fitted;
  auto e = (*model)->evaluate(setup, states);
  if (!e) return e.error();
  const Bands B = bands_of(**model, e->best, edges);
  std::string truth_regions;
  for (const auto& r : truth->at("regions")) truth_regions += (truth_regions.empty() ? "" : ",") + r.get<std::string>();
  const json& loc = report->at("localisation");
  double hem = 0.0, skirt = 0.0;
  for (const auto& r : loc.at("regions")) {
    if (r.at("region") == "hem") hem = r.at("enrichment").get<double>();
    if (r.at("region") == "skirt") skirt = r.at("enrichment").get<double>();
  }
  std::string cells;
  for (std::size_t b = 0; b < B.energy.size(); ++b) cells += fmt::format(" {:>6.2f}", B.enrichment(b));
  std::cout << fmt::format("{:<16} {:<12} {:<8} {:<12} {:>5.2f} {:>5.2f} |{} | {:>5.1f} {:>5.2f} {:>5.2f}\n", name,
                           truth_regions, loc.at("region").get<std::string>(), report->at("verdict").get<std::string>(),
                           hem, skirt, cells, 1e3 * sim::median(B.to_vertex), e->best.shape_all,
                           report->at("gap_tests").at("capture").at("shape").get<double>())
            << std::flush;
  rows.push_back({truth_regions, B.enrichment(0), skirt > 0.0 ? hem / skirt : 0.0});
  return {};
}

/// The run's diagnosed effect captures (placement 0; controls have no region to find).
sim::Expected<std::vector<std::string>> effect_cases(const fs::path& run) {
  std::vector<std::string> cases;
  std::error_code ec;
  for (const auto& entry : fs::directory_iterator(run / "diagnoses", ec)) {
    const std::string name = entry.path().stem().string();
    if (entry.path().extension() == ".json" && name.rfind("none_", 0) != 0 &&
        fs::exists(run / "truth" / (name + ".json"))) {
      cases.push_back(name);
    }
  }
  if (ec) return sim::Error{ec.message() + ": " + (run / "diagnoses").string()};
  std::sort(cases.begin(), cases.end());
  return cases;
}

}  // namespace

int main(int argc, char** argv) {
  drapegen::sim::relaunch_with_blas_kernels(argv);  // the kernels drapegen runs on (blas_kernels.hpp)
  CLI::App app{"drapegen region probe: a capture's residual on the hanging cloth, by material distance from the edge"};
  std::vector<std::string> runs, only;
  std::vector<double> edges_mm{25.0, 60.0};
  app.add_option("--run", runs, "drapegen_diagnosis_bench outputs (captures/, truth/, diagnoses/); the summary pools "
                                "them")
      ->required();
  app.add_option("--cases", only, "Case names (default: every diagnosed effect capture, placement 0)");
  app.add_option("--bands", edges_mm, "The bands' outer limits, mm of material distance from the free edge, rising "
                                      "(default 25 60: the hem's 25 mm, then to 60 mm, then the rest)")
      ->check(CLI::PositiveNumber);
  const auto settings = diagnosis::DiagnosisSettings::fine();
  CLI11_PARSE(app, argc, argv);
  if (!std::is_sorted(edges_mm.begin(), edges_mm.end())) {
    std::cerr << "region_probe: error: --bands must rise\n";
    return 1;
  }
  std::vector<double> edges;
  for (double mm : edges_mm) edges.push_back(1e-3 * mm);
  const auto states = diagnosis::validation_states(settings.attribution);
  std::string header;
  double lo = 0.0;
  for (double mm : edges_mm) header += fmt::format(" {:>6}", fmt::format("<{:g}", mm)), lo = mm;
  header += fmt::format(" {:>6}", fmt::format(">{:g}", lo));
  std::cout << "enrichment of the hanging cloth's residual per band of material distance from the free edge (mm); "
               "the report's hem and skirt enrichment; the pixels' median distance to the nearest vertex (mm); the "
               "fitted drape's shape distance here and as reported\n";
  std::cout << fmt::format("{:<16} {:<12} {:<8} {:<12} {:>5} {:>5} |{} | {:>5} {:>5} {:>5}\n", "case", "truth",
                           "region", "verdict", "hem", "skirt", header, "dist", "shape", "rep");
  int failed = 0, total = 0;
  std::vector<Row> rows;
  for (const auto& run : runs) {
    auto cases = only.empty() ? effect_cases(run) : sim::Expected<std::vector<std::string>>(only);
    if (!cases) {
      std::cerr << "region_probe: error: " << cases.error().message << "\n";
      return 1;
    }
    std::cout << run << "\n";
    for (const auto& name : *cases) {
      ++total;
      try {
        if (sim::Status s = probe_case(fs::path(run), name, settings, states, edges, rows); !s) {
          std::cerr << "region_probe: " << name << ": " << s.error().message << "\n";
          ++failed;
        }
      } catch (const json::exception& e) {  // a truth or report file without the expected fields
        std::cerr << "region_probe: " << name << ": " << e.what() << "\n";
        ++failed;
      }
    }
  }
  const auto count = [&](const char* region) {
    return std::count_if(rows.begin(), rows.end(), [&](const Row& r) { return r.truth == region; });
  };
  std::cout << fmt::format("effects at the hem ({}) above those at the skirt ({}) (1: apart, 0.5: mixed): outer band "
                           "{:.2f}, the report's hem over skirt {:.2f}\n",
                           count("hem"), count("skirt"), hem_above_skirt(rows, &Row::outer_band),
                           hem_above_skirt(rows, &Row::hem_over_skirt));
  if (failed > 0) std::cerr << "region_probe: " << failed << " of " << total << " cases failed\n";
  return failed > 0 ? 1 : 0;
}
