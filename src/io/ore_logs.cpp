#include "io/ore_logs.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cerrno>
#include <cstring>
#include <iterator>

#include "core/base/errors.hpp"
#include "io/output_dir.hpp"
#include "io/series.hpp"

namespace dem2d {

OreLogs::OreLogs(const std::string& directory, bool active, double continue_after_time)
    : product_path_(directory + "/" + kProductFile),
      breakages_path_(directory + "/" + kBreakagesFile),
      fragments_path_(directory + "/" + kFragmentsFile) {
  if (!active) return;
  for (auto [file, path, header] :
       {std::tuple{&product_, &product_path_, "time,id,radius,mass"},
        std::tuple{&breakages_, &breakages_path_,
                   "time,parent_id,radius,energy,fragments,first_fragment_id,mass,"
                   "specific_energy,t10,fines_mass"},
        std::tuple{&fragments_, &fragments_path_, "time,parent_id,id,radius,mass"}}) {
    if (continue_after_time >= 0.0) {
      file->reset(continue_csv(*path, header, 0, continue_after_time));
      continue;
    }
    file->reset(std::fopen(path->c_str(), "w"));
    if (!*file) throw IoError(fmt::format("cannot create {}: {}", *path, std::strerror(errno)));
    put(file->get(), *path, std::string(header) + "\n");
  }
}

void OreLogs::write(std::vector<BreakageRecord> breakages, std::vector<ProductRecord> product,
                    std::vector<FragmentRecord> fragments) {
  if (!product_) return;
  std::sort(breakages.begin(), breakages.end(), [](const auto& a, const auto& b) {
    return a.time < b.time || (a.time == b.time && a.parent < b.parent);
  });
  std::sort(product.begin(), product.end(), [](const auto& a, const auto& b) {
    return a.time < b.time || (a.time == b.time && a.id < b.id);
  });
  std::sort(fragments.begin(), fragments.end(), [](const auto& a, const auto& b) {
    return a.time < b.time || (a.time == b.time && a.id < b.id);
  });
  std::string text;
  for (const ProductRecord& r : product)
    fmt::format_to(std::back_inserter(text), "{:.17g},{},{:.17g},{:.17g}\n", r.time, r.id, r.radius,
                   r.mass);
  if (!text.empty()) put(product_.get(), product_path_, text);
  text.clear();
  for (const BreakageRecord& r : breakages)
    fmt::format_to(std::back_inserter(text),
                   "{:.17g},{},{:.17g},{:.17g},{},{},{:.17g},{:.17g},{:.17g},{:.17g}\n", r.time,
                   r.parent, r.radius, r.energy, r.fragments, r.first_id, r.mass, r.specific_energy,
                   r.t10, r.fines_mass);
  if (!text.empty()) put(breakages_.get(), breakages_path_, text);
  text.clear();
  for (const FragmentRecord& r : fragments)
    fmt::format_to(std::back_inserter(text), "{:.17g},{},{},{:.17g},{:.17g}\n", r.time, r.parent,
                   r.id, r.radius, r.mass);
  if (!text.empty()) put(fragments_.get(), fragments_path_, text);
}

void OreLogs::put(std::FILE* f, const std::string& path, const std::string& text) {
  append_to_log(f, path, text);
}

}  // namespace dem2d
