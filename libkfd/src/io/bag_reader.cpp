#include "bag_reader.h"

#include <rosbag/query.h>

#include <algorithm>

#include "kfd/io/bag_source.h"

namespace kfd {
namespace {

// A rosbag::View whose message ranges (per connection: its index entries, from rosbag's index)
// can be walked without rosbag reading the messages.
class IndexView : public rosbag::View {
  public:
    using rosbag::View::View;
    const std::vector<rosbag::MessageRange*>& ranges() const { return ranges_; }
};

// rosbag::View::iterator's state: one position per range, sorted so that back() is the next
// message (the earliest time). Sorting the same sequence with the same comparison as View does
// gives the same order, ties included.
struct Position {
    std::multiset<rosbag::IndexEntry>::const_iterator iter;
    const rosbag::MessageRange* range;
};
struct Later {
    bool operator()(const Position& a, const Position& b) const {
        return a.iter->time > b.iter->time;
    }
};

}  // namespace

struct BagReader::Cursor::Impl {
    BagReader* reader;
    std::unique_ptr<IndexView> view;
    std::vector<Position> positions;
    bool consuming;
    std::size_t size = 0;
};

BagReader::Cursor::Cursor(std::unique_ptr<Impl> impl) : impl_(std::move(impl)) {}
BagReader::Cursor::~Cursor() = default;
BagReader::Cursor::Cursor(Cursor&&) noexcept = default;
std::size_t BagReader::Cursor::size() const { return impl_->size; }

bool BagReader::Cursor::next(NativeMessage& out) {
    Impl& d = *impl_;
    if (d.positions.empty()) return false;
    const Position at = d.positions.back();
    const rosbag::IndexEntry& e = *at.iter;
    // The position moves on first: a message that cannot be read is not read again.
    if (++d.positions.back().iter == at.range->end) d.positions.pop_back();
    std::sort(d.positions.begin(), d.positions.end(), Later());

    const auto chunk = d.reader->chunkAt(e.chunk_pos);
    const ChunkMessage* m = chunk->find(e.offset);
    if (!m)
        d.reader->file_.fail(e.chunk_pos,
                             "an index entry points to no message of its chunk (corrupt)");
    out.connection = at.range->connection_info;
    out.time = e.time;
    out.bytes.assign(chunk->plain.begin() + m->data, chunk->plain.begin() + m->data + m->size);
    if (d.consuming) d.reader->consumed(e.chunk_pos);
    return true;
}

BagReader::BagReader(BagFile& file, const rosbag::Bag& bag, std::uint64_t cache_bytes)
    : file_(file), bag_(bag), cache_bytes_(cache_bytes) {
    IndexView all(bag);
    for (const rosbag::MessageRange* r : all.ranges())
        for (auto it = r->begin; it != r->end; ++it) ++unread_[it->chunk_pos];
}
BagReader::~BagReader() = default;

BagReader::Cursor BagReader::cursor(const std::string& topic, bool consuming) {
    auto d = std::make_unique<Cursor::Impl>();
    d->reader = this;
    d->consuming = consuming;
    d->view = topic.empty() ? std::make_unique<IndexView>(bag_)
                            : std::make_unique<IndexView>(bag_, rosbag::TopicQuery(topic));
    for (const rosbag::MessageRange* r : d->view->ranges())
        if (r->begin != r->end) {
            d->positions.push_back(Position{r->begin, r});
            d->size += static_cast<std::size_t>(std::distance(r->begin, r->end));
        }
    std::sort(d->positions.begin(), d->positions.end(), Later());
    return Cursor(std::move(d));
}

std::shared_ptr<const Chunk> BagReader::chunkAt(std::uint64_t pos) {
    ++tick_;
    const auto it = cache_.find(pos);
    if (it != cache_.end()) {
        it->second.used = tick_;
        return it->second.chunk;
    }
    auto chunk = std::make_shared<Chunk>();
    file_.readChunk(pos, *chunk);
    // Room for it: the least recently used chunks go.
    while (!cache_.empty() && cached_bytes_ + chunk->plain.size() > cache_bytes_) {
        auto lru = cache_.begin();
        for (auto c = cache_.begin(); c != cache_.end(); ++c)
            if (c->second.used < lru->second.used) lru = c;
        cached_bytes_ -= lru->second.chunk->plain.size();
        cache_.erase(lru);
    }
    cached_bytes_ += chunk->plain.size();
    cache_[pos] = Cached{chunk, tick_};
    return chunk;
}

void BagReader::consumed(std::uint64_t pos) {
    auto& left = unread_[pos];
    if (left > 0 && --left == 0) {  // the chunk's last message: it is not needed again
        const auto it = cache_.find(pos);
        if (it != cache_.end()) {
            cached_bytes_ -= it->second.chunk->plain.size();
            cache_.erase(it);
        }
    }
}

std::size_t BagReader::chunksLoaded() const { return file_.chunksLoaded(); }
std::size_t BagReader::chunks() const { return file_.chunks(); }

}  // namespace kfd
