#pragma once
// Dense ids for distinct keys, in first-seen order: joining the vertices of a brick by position
// and attributes (preprocess) and the corners of its faces into Draco points (store). An open
// addressing table with linear probing; std::unordered_map allocated a node per key, which cost
// more than the joining itself on bricks of a million vertices.

#include <bit>
#include <cstdint>
#include <cstring>
#include <type_traits>
#include <vector>

namespace nave {

/// Keys are compared and hashed by their bytes, so they must have no padding; a key is a whole
/// number of 32-bit words. Not thread-safe; Reset() keeps the memory for the next brick.
template <typename Key>
class KeyTable {
    static_assert(std::has_unique_object_representations_v<Key>,
                  "KeyTable keys are compared by bytes: no padding, no floats (bit_cast them)");
    static_assert(sizeof(Key) % 4 == 0, "KeyTable keys are hashed by 32-bit words");

  public:
    /// Empties the table and sizes it for up to `max_keys` keys (at most half full).
    void Reset(size_t max_keys) {
        keys_.clear();
        keys_.reserve(max_keys);
        size_t slots = 16;
        while (slots < 2 * max_keys + 16) slots <<= 1;
        slots_.assign(slots, 0);
        mask_ = slots - 1;
    }

    /// The id of `key`, inserting it with the next id if it is new (`*inserted` says which).
    /// At most the `max_keys` given to Reset() may be inserted.
    uint32_t Insert(const Key& key, bool* inserted) {
        size_t i = Hash(key) & mask_;
        while (true) {
            const uint32_t s = slots_[i];
            if (s == 0) {
                const uint32_t id = uint32_t(keys_.size());
                slots_[i] = id + 1;
                keys_.push_back(key);
                *inserted = true;
                return id;
            }
            if (std::memcmp(&keys_[s - 1], &key, sizeof(Key)) == 0) {
                *inserted = false;
                return s - 1;
            }
            i = (i + 1) & mask_;
        }
    }
    uint32_t Insert(const Key& key) {
        bool inserted = false;
        return Insert(key, &inserted);
    }

    const Key& key(uint32_t id) const { return keys_[id]; }
    size_t size() const { return keys_.size(); }

  private:
    static uint64_t Hash(const Key& key) {
        uint32_t words[sizeof(Key) / 4];
        std::memcpy(words, &key, sizeof(Key));
        uint64_t h = 0x9E3779B97F4A7C15ull;
        for (uint32_t w : words) {
            h ^= w + 0x9E3779B97F4A7C15ull + (h << 6) + (h >> 2);
            h *= 0xBF58476D1CE4E5B9ull;
        }
        return h ^ (h >> 29);
    }

    std::vector<Key> keys_;
    std::vector<uint32_t> slots_;  ///< key id + 1; 0 is an empty slot
    size_t mask_ = 0;
};

}  // namespace nave
