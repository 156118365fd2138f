// OMG CDR (XCDR1, "plain CDR"), the serialization of ROS 2 messages in rosbag2 files, MCAP's
// `cdr` encoding and on the DDS wire: a 4-byte encapsulation header (00 00 big-endian, 00 01
// little-endian, then 2 option bytes), then the fields, each aligned to its own size counted
// from the end of the header (8-byte values to 8). Strings: uint32 length counting a closing
// NUL, the bytes, the NUL. Sequences: uint32 count, then the elements. Private to libkfd (the
// ROS 2 message layer's); std only.
#pragma once

#include <cstddef>
#include <cstdint>
#include <cstring>
#include <stdexcept>
#include <string>
#include <vector>

namespace kfd {

/// True on a little-endian machine (CDR's byte order flag).
inline bool hostLittle() {
    const std::uint16_t one = 1;
    std::uint8_t b;
    std::memcpy(&b, &one, 1);
    return b == 1;
}

/// Bytes that are not the CDR the reader expects: what.
class CdrError : public std::runtime_error {
  public:
    using std::runtime_error::runtime_error;
};

/// Reads CDR from a byte range it does not own. Every read is checked against the bytes left
/// before anything is allocated (a sequence's count times its element size must fit): a
/// message that lies about a length costs nothing.
class CdrReader {
  public:
    /// Reads the encapsulation header: CdrError when it is shorter than 4 bytes or is not
    /// plain CDR (big- or little-endian).
    CdrReader(const std::uint8_t* data, std::size_t size) : data_(data), size_(size) {
        if (size < 4) throw CdrError("shorter than the 4-byte CDR header");
        if (data[0] != 0 || (data[1] != 0 && data[1] != 1))
            throw CdrError("not plain CDR (encapsulation " + hex(data[0]) + " " + hex(data[1]) +
                           ")");
        little_ = data[1] == 1;
        pos_ = 4;
    }

    /// `field` names the value in errors ("ranges").
    template <class T>
    T read(const char* field) {
        align(sizeof(T), field);
        need(sizeof(T), field);
        T v;
        std::memcpy(&v, data_ + pos_, sizeof(T));
        if (little_ != hostLittle()) swap(v);
        pos_ += sizeof(T);
        return v;
    }

    std::string readString(const char* field) {
        const std::uint32_t n = read<std::uint32_t>(field);
        if (n == 0) return {};  // some writers omit the NUL of an empty string
        if (n > left())
            throw CdrError(std::string(field) + ": string length " + std::to_string(n) +
                           " does not fit in the " + std::to_string(left()) + " bytes left");
        std::string s(reinterpret_cast<const char*>(data_ + pos_), n - 1);
        pos_ += n;
        return s;
    }

    /// The count of a sequence whose elements take at least `min_element` bytes each.
    std::uint32_t readCount(const char* field, std::size_t min_element) {
        const std::uint32_t n = read<std::uint32_t>(field);
        if (min_element && static_cast<std::uint64_t>(n) * min_element > left())
            throw CdrError(std::string(field) + ": sequence length " + std::to_string(n) + " (" +
                           std::to_string(static_cast<std::uint64_t>(n) * min_element) +
                           " bytes) does not fit in the " + std::to_string(left()) + " bytes left");
        return n;
    }

    template <class T>
    void readSequence(std::vector<T>& out, const char* field) {
        const std::uint32_t n = readCount(field, sizeof(T));
        if (n) align(sizeof(T), field);
        need(static_cast<std::size_t>(n) * sizeof(T), field);
        out.resize(n);
        for (auto& v : out) v = read<T>(field);
    }

    std::size_t left() const { return size_ - pos_; }

  private:
    template <class T>
    static void swap(T& v) {
        std::uint8_t b[sizeof(T)];
        std::memcpy(b, &v, sizeof(T));
        for (std::size_t i = 0; i < sizeof(T) / 2; ++i) std::swap(b[i], b[sizeof(T) - 1 - i]);
        std::memcpy(&v, b, sizeof(T));
    }
    static std::string hex(std::uint8_t b) {
        const char* d = "0123456789abcdef";
        return std::string{d[b >> 4], d[b & 15]};
    }
    void align(std::size_t n, const char* field) {
        const std::size_t off = (pos_ - 4) % n;
        if (off) {
            need(n - off, field);
            pos_ += n - off;
        }
    }
    void need(std::size_t n, const char* field) const {
        if (n > left())
            throw CdrError(std::string(field) + ": " + std::to_string(n) +
                           " bytes needed, the message has " + std::to_string(left()) + " left");
    }

    const std::uint8_t* data_;
    std::size_t size_, pos_ = 0;
    bool little_ = true;
};

/// Writes CDR in the host's byte order (little-endian on x86 and ARM, as ROS 2 does), header
/// included.
class CdrWriter {
  public:
    CdrWriter() : out_{0, hostLittle() ? std::uint8_t{1} : std::uint8_t{0}, 0, 0} {}

    template <class T>
    void write(T v) {
        align(sizeof(T));
        const std::size_t at = out_.size();
        out_.resize(at + sizeof(T));
        std::memcpy(out_.data() + at, &v, sizeof(T));  // the host's order, as the header says
    }
    void writeString(const std::string& s) {
        write<std::uint32_t>(static_cast<std::uint32_t>(s.size() + 1));
        out_.insert(out_.end(), s.begin(), s.end());
        out_.push_back(0);
    }
    template <class T>
    void writeSequence(const std::vector<T>& v) {
        write<std::uint32_t>(static_cast<std::uint32_t>(v.size()));
        for (const T& x : v) write<T>(x);
    }
    std::vector<std::uint8_t>& bytes() { return out_; }

  private:
    void align(std::size_t n) {
        const std::size_t off = (out_.size() - 4) % n;
        if (off) out_.resize(out_.size() + n - off, 0);
    }
    std::vector<std::uint8_t> out_;
};

}  // namespace kfd
