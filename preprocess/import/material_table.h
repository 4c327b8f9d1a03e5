#pragma once
// Materials made from names and colours, for importers whose files name parts, layers or entity
// types and colour them (STEP, IGES, IFC, DXF) rather than define materials: one record per name
// and colour, so that a name keeps its own colour. The first colour met under a name keeps the
// name; further colours get "name #2", "name #3"... in the order they are met.

#include <fmt/format.h>

#include <array>
#include <cmath>
#include <map>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "store/material_record.h"

namespace nave::preprocess {

class MaterialTable {
  public:
    /// Appends to `records` (which must outlive the table).
    explicit MaterialTable(std::vector<store::MaterialRecord>& records) : records_(records) {}

    /// The index of the record for `name` in `rgba` (linear RGB and alpha, each in [0, 1]; none:
    /// the record's default grey), added when new. Colours equal to 8 bits are one.
    uint32_t Find(const std::string& name, const std::optional<std::array<float, 4>>& rgba) {
        std::array<int, 4> key{-1, -1, -1, -1};
        if (rgba) {
            for (int k = 0; k < 4; ++k) key[k] = Quantize((*rgba)[k]);
        }
        auto [it, added] = index_.try_emplace({name, key}, uint32_t(records_.size()));
        if (!added) return it->second;
        const int nth = ++colours_per_name_[name];
        store::MaterialRecord m;
        m.name = nth == 1 ? name : fmt::format("{} #{}", name, nth);
        if (rgba) {
            m.diffuse = {(*rgba)[0], (*rgba)[1], (*rgba)[2]};
            m.opacity = (*rgba)[3];
        }
        records_.push_back(std::move(m));
        return it->second;
    }

  private:
    static int Quantize(float v) {
        return int(std::lround(std::fmin(std::fmax(double(v), 0.0), 1.0) * 255.0));
    }

    std::vector<store::MaterialRecord>& records_;
    std::map<std::pair<std::string, std::array<int, 4>>, uint32_t> index_;
    std::map<std::string, int> colours_per_name_;
};

}  // namespace nave::preprocess
