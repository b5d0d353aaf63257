#include "io/ply/ply_reader.hpp"

#include "io/decimal_text.hpp"
#include "io/file_stream.hpp"
#include "io/input_error.hpp"
#include "io/line_reader.hpp"
#include "io/parallel_record_scan.hpp"
#include "io/ply/ply_float_records.hpp"
#include "io/ply/ply_header.hpp"
#include "io/ply/ply_values.hpp"
#include "io/pre_pass_monitor.hpp"
#include "io/record_block_reader.hpp"
#include "io/source_normalizer.hpp"
#include "io/text_blocks.hpp"

#include <algorithm>
#include <array>
#include <bit>
#include <cctype>
#include <cmath>
#include <cstring>
#include <initializer_list>
#include <optional>
#include <tbb/enumerable_thread_specific.h>

namespace omicron {

namespace {

// Whole records per read() call. Small enough that the block is still in L2 when the
// extraction loop reads it back, large enough that the syscall cost disappears (1 MiB measured
// faster than 256 KiB and 4 MiB on autzen_south.ply).
constexpr std::size_t kBlockBytes = 1 << 20;

// ---- which vertex properties feed which attribute ------------------------------------------

struct VertexFields {
    std::array<int, 3> position{-1, -1, -1}; // property indices; -1: absent
    std::array<int, 3> normal{-1, -1, -1};
    std::array<int, 3> color{-1, -1, -1};
    int intensity = -1;

    bool hasNormals() const { return normal[0] >= 0; }
    bool hasColors() const { return color[0] >= 0; }
    bool hasIntensity() const { return intensity >= 0; }
};

int findPropertyIgnoringCase(const PlyElement& element, std::string_view lowerCaseName) {
    for (std::size_t index = 0; index < element.properties.size(); ++index) {
        const std::string& name = element.properties[index].name;
        if (std::equal(
                name.begin(), name.end(), lowerCaseName.begin(), lowerCaseName.end(),
                [](char a, char b) { return std::tolower(static_cast<unsigned char>(a)) == b; })) {
            return static_cast<int>(index);
        }
    }
    return -1;
}

// The first spelling whose three names are all scalar properties of `vertex`.
std::array<int, 3> findTriple(const PlyElement& vertex,
                              std::initializer_list<std::array<const char*, 3>> spellings) {
    for (const std::array<const char*, 3>& names : spellings) {
        std::array<int, 3> found{};
        bool complete = true;
        for (int axis = 0; axis < 3; ++axis) {
            found[axis] = vertex.findProperty(names[axis]);
            complete = complete && found[axis] >= 0 && !vertex.properties[found[axis]].isList;
        }
        if (complete) {
            return found;
        }
    }
    return {-1, -1, -1};
}

// ---- batch delivery -----------------------------------------------------------------------

// Owns the reused batch: its vectors stay sized to the capacity while points are written by
// index (no push_back in the hot loops) and shrink only for the last, partial batch.
class BatchSink {
public:
    BatchSink(AttributeSet attributes, std::size_t capacity, const ReadOptions& options,
              const BatchConsumer& consumer, ReadSummary& summary)
        : m_capacity(capacity), m_options(options), m_consumer(consumer), m_summary(summary) {
        m_batch.attributes = attributes;
        resizeAll(capacity);
    }

    std::size_t room() const { return m_capacity - m_filled; }
    std::size_t filled() const { return m_filled; }
    PointBatch& batch() { return m_batch; }

    // Accepts `count` points written at filled()...; delivers a full batch. False when the
    // caller must stop because the read was cancelled.
    bool commit(std::size_t count) {
        m_filled += count;
        return m_filled < m_capacity || deliver();
    }

    // Delivers the last, partial batch.
    void finish() {
        if (m_filled > 0) {
            resizeAll(m_filled);
            deliver();
        }
    }

private:
    void resizeAll(std::size_t count) {
        m_batch.positions.resize(count);
        if (m_batch.attributes.has(Attribute::Normal)) {
            m_batch.normals.resize(count);
        }
        if (m_batch.attributes.has(Attribute::Color)) {
            m_batch.colors.resize(count);
        }
        if (m_batch.attributes.has(Attribute::Intensity)) {
            m_batch.intensities.resize(count);
        }
    }

    bool deliver() {
        m_consumer(m_batch);
        m_summary.pointsDelivered += m_filled;
        ++m_summary.batches;
        m_filled = 0;
        if (m_options.cancel != nullptr && m_options.cancel->load(std::memory_order_relaxed)) {
            m_summary.cancelled = true;
            return false;
        }
        return true;
    }

    PointBatch m_batch;
    std::size_t m_capacity;
    std::size_t m_filled = 0;
    const ReadOptions& m_options;
    const BatchConsumer& m_consumer;
    ReadSummary& m_summary;
};

// ---- ascii values -------------------------------------------------------------------------

std::string_view nextWord(const char*& cursor, const char* end) {
    while (cursor < end && (*cursor == ' ' || *cursor == '\t')) {
        ++cursor;
    }
    const char* start = cursor;
    while (cursor < end && *cursor != ' ' && *cursor != '\t') {
        ++cursor;
    }
    return {start, static_cast<std::size_t>(cursor - start)};
}

bool isBlank(std::string_view line) {
    return line.find_first_not_of(" \t\r") == std::string_view::npos;
}

// Next line holding data: blank lines (a trailing empty line, say) carry no record.
bool nextDataLine(LineReader& lines, std::string_view& line) {
    while (lines.next(line)) {
        if (!isBlank(line)) {
            return true;
        }
    }
    return false;
}

// The vertex lines of one text block, parsed on any thread (io/text_blocks.hpp): the values
// of each line that parses as a vertex, and the first line that does not, which ends the
// block's parse. A block does not know which vertex it starts with, nor whether the vertices
// end inside it: the merge numbers them and decides whether that line is an error.
struct AsciiVertexLines {
    std::vector<double> values;       // the properties' values, line after line
    std::vector<std::uint64_t> lines; // the line number of each
    bool stopped = false;             // a line that is no vertex ended the parse
    std::uint64_t stopLine = 0;
    std::string stopDetail; // what is wrong with it as a vertex
};

// ---- the reader ---------------------------------------------------------------------------

class PlyReader final : public PointReader {
public:
    PlyReader(const std::string& path, const OpenOptions& options);
    ReadSummary read(const BatchConsumer& consumer, const ReadOptions& options) override;

private:
    const PlyElement& vertex() const { return m_header.elements[m_vertexElement]; }
    bool binary() const { return m_header.format != CloudFormat::PlyAscii; }

    void findVertexElement();
    void resolveFields();
    void locateVertexBody();
    void checkFixedBodySize() const;
    void checkAsciiBodySize() const;
    void describeFormat();
    void runBoundsPrePass(const OpenOptions& options);

    std::uint64_t walkRecords(PlyBodyCursor& cursor, const PlyElement& element, std::uint64_t index,
                              const std::uint8_t* useMask, double* values) const;
    template <typename OnVertex> bool visitAscii(OnVertex&& onVertex);
    std::string parseAsciiVertex(std::string_view line, double* values) const;
    void parseAsciiVertexLines(const TextBlock& block, AsciiVertexLines& out) const;
    template <typename OnVertex> bool visitVariableRecords(OnVertex&& onVertex);
    template <typename OnBlock> bool visitFixedBlocks(OnBlock&& onBlock);
    template <typename OnVertex> bool visitVertexValues(OnVertex&& onVertex);
    // `swapBytes`: the record is still in the file's foreign byte order.
    void loadUsedValues(const std::uint8_t* record, double* values, bool swapBytes) const;
    // Fixed records of a foreign-endian file into the host's order, in place, for the fast loops.
    void toNativeOrder(std::uint8_t* records, std::size_t count) const;
    bool hasType(const std::array<int, 3>& fields, PlyScalarType type) const;
    bool fastPositions() const;
    // The fast loops' type of each optional attribute (None when the file has none), or
    // nullopt when they do not read the file's type.
    std::optional<FloatRecordLayout::Normals> fastNormals() const;
    std::optional<FloatRecordLayout::Color> fastColors() const;
    // fastNormals and fastColors: None when the file has no such fields, else the loops' type
    // paired with the first of `types` all three of `fields` have, or nullopt.
    template <typename Loops>
    std::optional<Loops>
    fastTriple(bool present, const std::array<int, 3>& fields,
               std::initializer_list<std::pair<PlyScalarType, Loops>> types) const;
    std::optional<FloatRecordLayout::Intensity> fastIntensity() const;
    bool fastLayout() const;
    FloatRecordLayout floatLayout() const;
    void scanFixedRecordBounds(PrePassMonitor& monitor, Bounds& bounds, std::uint64_t& finite);
    bool readFastLayout(const SourceNormalizer& normalizer, BatchSink& sink, ReadSummary& summary);
    bool addVertex(const double* values, const SourceNormalizer& normalizer, BatchSink& sink,
                   ReadSummary& summary, InputLocation where) const;

    [[noreturn]] void throwNoFinitePoints() const;

    // Binary records are found by byte offset, ascii vertices by line.
    InputLocation vertexLocation(std::uint64_t byteOrLine) const {
        return binary() ? InputLocation::byte(byteOrLine) : InputLocation::line(byteOrLine);
    }

    FileStream m_stream;
    PlyHeader m_header;
    std::size_t m_vertexElement = 0;
    bool m_vertexIsLast = false;
    VertexFields m_fields;
    std::vector<std::uint8_t> m_usedProperty;     // 1 where a vertex property feeds an attribute
    std::vector<int> m_usedProperties;            // their indices
    std::vector<std::uint32_t> m_propertyOffsets; // fixed records: byte offset of each property
    std::string m_propertyNames;                  // "x y z red green blue", for messages
    bool m_swapBytes = false;
    // Fixed records with m_swapBytes: offset and size of each property wider than a byte.
    std::vector<std::pair<std::uint32_t, std::uint8_t>> m_swapFields;
    bool m_fixedRecords = false;
    std::uint64_t m_recordBytes = 0;
    std::uint64_t m_vertexStart = 0;     // byte offset of the first vertex record or line
    std::uint64_t m_vertexFirstLine = 0; // ascii: line number of the first vertex
    std::uint64_t m_asciiProgress = 0;   // ascii: the end of the block being visited
};

PlyReader::PlyReader(const std::string& path, const OpenOptions& options) : m_stream(path) {
    m_header = parsePlyHeader(m_stream);
    m_swapBytes = binary() && ((m_header.format == CloudFormat::PlyBinaryBigEndian) !=
                               (std::endian::native == std::endian::big));
    findVertexElement();
    resolveFields();

    m_info.path = path;
    m_info.format = m_header.format;
    m_info.pointCount = vertex().count;
    m_info.sourceOffset = m_header.offset;
    if (vertex().count == 0) {
        throw InputError(InputErrorKind::NoPoints, path, InputLocation::line(vertex().headerLine),
                         "element 'vertex' declares 0 vertices; expected at least one point");
    }
    locateVertexBody();
    describeFormat();

    if (options.knownBounds) {
        m_info.sourceBounds = *options.knownBounds;
    } else {
        runBoundsPrePass(options);
    }
    m_info.boundsFromHeader = false;
    m_info.cube = CubeTransform::fromBounds(m_info.sourceBounds);
}

void PlyReader::findVertexElement() {
    for (std::size_t index = 0; index < m_header.elements.size(); ++index) {
        if (m_header.elements[index].name == "vertex") {
            m_vertexElement = index;
            m_vertexIsLast = index + 1 == m_header.elements.size();
            return;
        }
    }
    std::string declared;
    for (const PlyElement& element : m_header.elements) {
        declared += (declared.empty() ? "'" : ", '") + element.name + "'";
    }
    throw InputError(
        InputErrorKind::MalformedHeader, m_stream.path(),
        InputLocation::line(m_header.endHeaderLine),
        "expected an 'element vertex N' line before 'end_header', found " +
            (declared.empty() ? std::string("no elements") : "only elements " + declared));
}

void PlyReader::resolveFields() {
    const PlyElement& element = vertex();
    for (const PlyProperty& property : element.properties) {
        m_propertyNames += (m_propertyNames.empty() ? "" : " ") + property.name;
    }
    static constexpr std::array<const char*, 3> kAxes{"x", "y", "z"};
    for (int axis = 0; axis < 3; ++axis) {
        const int index = element.findProperty(kAxes[axis]);
        if (index < 0) {
            throw InputError(InputErrorKind::MalformedHeader, m_stream.path(),
                             InputLocation::line(element.headerLine),
                             std::string("element 'vertex' has no property '") + kAxes[axis] +
                                 "'; expected x, y and z, found: " + m_propertyNames);
        }
        if (element.properties[index].isList) {
            throw InputError(InputErrorKind::MalformedHeader, m_stream.path(),
                             InputLocation::line(element.headerLine),
                             std::string("vertex property '") + kAxes[axis] +
                                 "' is a list; expected a scalar coordinate");
        }
        m_fields.position[axis] = index;
    }
    m_fields.normal =
        findTriple(element, {{"nx", "ny", "nz"}, {"normal_x", "normal_y", "normal_z"}});
    m_fields.color = findTriple(element, {{"red", "green", "blue"},
                                          {"r", "g", "b"},
                                          {"diffuse_red", "diffuse_green", "diffuse_blue"}});
    // In any case: CloudCompare writes its scalar fields as "scalar_" and the field's name
    // ("scalar_Intensity").
    for (const std::string_view name : {"intensity", "scalar_intensity"}) {
        const int index = findPropertyIgnoringCase(element, name);
        if (index >= 0 && !element.properties[index].isList) {
            m_fields.intensity = index;
            break;
        }
    }

    m_usedProperty.assign(element.properties.size(), 0);
    const auto use = [&](int index) {
        if (index >= 0) {
            m_usedProperty[index] = 1;
        }
    };
    for (int axis = 0; axis < 3; ++axis) {
        use(m_fields.position[axis]);
        use(m_fields.normal[axis]);
        use(m_fields.color[axis]);
    }
    use(m_fields.intensity);
    for (std::size_t p = 0; p < m_usedProperty.size(); ++p) {
        if (m_usedProperty[p] != 0) {
            m_usedProperties.push_back(static_cast<int>(p));
        }
    }
    if (m_fields.hasNormals()) {
        m_info.attributes.add(Attribute::Normal);
    }
    if (m_fields.hasColors()) {
        m_info.attributes.add(Attribute::Color);
    }
    if (m_fields.hasIntensity()) {
        m_info.attributes.add(Attribute::Intensity);
    }

    m_fixedRecords = !element.hasLists();
    if (m_fixedRecords) {
        m_recordBytes = element.recordBytes();
        std::uint32_t offset = 0;
        for (const PlyProperty& property : element.properties) {
            m_propertyOffsets.push_back(offset);
            const std::size_t bytes = plyScalarBytes(property.type);
            if (m_swapBytes && bytes > 1) {
                m_swapFields.emplace_back(offset, static_cast<std::uint8_t>(bytes));
            }
            offset += static_cast<std::uint32_t>(bytes);
        }
    }
}

// Reads one record per element instance from `cursor`, keeping the values of properties that
// `useMask` marks (null: none). Returns the record's starting offset; throws on a short file.
std::uint64_t PlyReader::walkRecords(PlyBodyCursor& cursor, const PlyElement& element,
                                     std::uint64_t index, const std::uint8_t* useMask,
                                     double* values) const {
    const std::uint64_t recordStart = cursor.offset();
    const auto truncated = [&](const PlyProperty& property) {
        throw InputError(InputErrorKind::Truncated, m_stream.path(),
                         InputLocation::byte(recordStart),
                         "expected property '" + property.name + "' of " + element.name + " " +
                             std::to_string(index) + " (of " + std::to_string(element.count) +
                             "), but the file ends at byte " + std::to_string(m_stream.size()));
    };
    for (std::size_t p = 0; p < element.properties.size(); ++p) {
        const PlyProperty& property = element.properties[p];
        if (!property.isList) {
            const std::uint8_t* bytes = cursor.take(plyScalarBytes(property.type));
            if (bytes == nullptr) {
                truncated(property);
            }
            if (useMask != nullptr && useMask[p] != 0) {
                values[p] = loadPlyScalar(bytes, property.type, m_swapBytes);
            }
            continue;
        }
        const std::uint64_t countOffset = cursor.offset();
        const std::uint8_t* bytes = cursor.take(plyScalarBytes(property.countType));
        if (bytes == nullptr) {
            truncated(property);
        }
        const double items = loadPlyScalar(bytes, property.countType, m_swapBytes);
        if (items < 0.0) {
            throw InputError(
                InputErrorKind::MalformedValue, m_stream.path(), InputLocation::byte(countOffset),
                "list '" + property.name + "' of " + element.name + " " + std::to_string(index) +
                    " has a negative length " + std::to_string(static_cast<long long>(items)) +
                    "; expected a count >= 0");
        }
        if (!cursor.skip(static_cast<std::uint64_t>(items) * plyScalarBytes(property.type))) {
            truncated(property);
        }
    }
    return recordStart;
}

void PlyReader::locateVertexBody() {
    const std::string& path = m_stream.path();
    if (!binary()) {
        m_stream.seek(m_header.bodyOffset);
        LineReader lines(m_stream, m_header.bodyFirstLine);
        std::string_view line;
        for (std::size_t e = 0; e < m_vertexElement; ++e) {
            const PlyElement& element = m_header.elements[e];
            for (std::uint64_t index = 0; index < element.count; ++index) {
                if (!nextDataLine(lines, line)) {
                    throw InputError(InputErrorKind::Truncated, path,
                                     InputLocation::line(lines.lineNumber() + 1),
                                     "expected " + std::to_string(element.count) + " '" +
                                         element.name +
                                         "' lines before the vertices, but the "
                                         "file ends after " +
                                         std::to_string(index));
                }
            }
        }
        if (!nextDataLine(lines, line)) {
            throw InputError(InputErrorKind::Truncated, path,
                             InputLocation::line(lines.lineNumber() + 1),
                             "expected " + std::to_string(vertex().count) +
                                 " vertex lines, but the file ends before the first");
        }
        m_vertexStart = lines.lineOffset();
        m_vertexFirstLine = lines.lineNumber();
        checkAsciiBodySize();
        return;
    }

    std::uint64_t offset = m_header.bodyOffset;
    for (std::size_t e = 0; e < m_vertexElement; ++e) {
        const PlyElement& element = m_header.elements[e];
        if (!element.hasLists()) {
            const std::uint64_t bytes = element.count * element.recordBytes(); // header-checked
            if (bytes > m_stream.size() - std::min(offset, m_stream.size())) {
                throw InputError(InputErrorKind::Truncated, path, InputLocation::byte(offset),
                                 "expected " + std::to_string(element.count) + " '" + element.name +
                                     "' records of " + std::to_string(element.recordBytes()) +
                                     " bytes before the vertices, but the file ends at byte " +
                                     std::to_string(m_stream.size()));
            }
            offset += bytes;
            continue;
        }
        PlyBodyCursor cursor(m_stream, offset);
        for (std::uint64_t index = 0; index < element.count; ++index) {
            walkRecords(cursor, element, index, nullptr, nullptr);
        }
        offset = cursor.offset();
    }
    m_vertexStart = offset;
    if (m_fixedRecords) {
        checkFixedBodySize();
    }
}

void PlyReader::checkFixedBodySize() const {
    const std::uint64_t available = m_stream.size() - std::min(m_vertexStart, m_stream.size());
    const std::uint64_t count = vertex().count;
    if (count > available / m_recordBytes) {
        const std::uint64_t firstMissing = available / m_recordBytes;
        throw InputError(InputErrorKind::Truncated, m_stream.path(),
                         InputLocation::byte(m_vertexStart + firstMissing * m_recordBytes),
                         "expected vertex " + std::to_string(firstMissing) + " of " +
                             std::to_string(count) + " (" + std::to_string(m_recordBytes) +
                             "-byte records from byte " + std::to_string(m_vertexStart) +
                             "), but the file ends at byte " + std::to_string(m_stream.size()));
    }
    const std::uint64_t end = m_vertexStart + count * m_recordBytes;
    if (m_vertexIsLast && end < m_stream.size()) {
        throw InputError(InputErrorKind::CountMismatch, m_stream.path(), InputLocation::byte(end),
                         "expected the file to end after " + std::to_string(count) +
                             " vertices of " + std::to_string(m_recordBytes) + " bytes, but " +
                             std::to_string(m_stream.size() - end) +
                             " more bytes follow (is the header's vertex count too small?)");
    }
}

void PlyReader::checkAsciiBodySize() const {
    // Every value takes at least a digit and a separator: a cheap bound that stops an absurd
    // count (which loadPointCloud would reserve memory for) before any real work.
    const std::uint64_t bytesPerVertex = 2 * std::max<std::uint64_t>(vertex().properties.size(), 1);
    const std::uint64_t available = m_stream.size() - m_vertexStart;
    if (vertex().count > available / bytesPerVertex + 1) {
        throw InputError(InputErrorKind::Truncated, m_stream.path(),
                         InputLocation::line(m_vertexFirstLine),
                         "the header declares " + std::to_string(vertex().count) + " vertices of " +
                             std::to_string(vertex().properties.size()) +
                             " values (at least 2 bytes each), but only " +
                             std::to_string(available) + " bytes follow");
    }
}

void PlyReader::describeFormat() {
    static constexpr std::array<const char*, 3> kNames{"ascii", "binary_little_endian",
                                                       "binary_big_endian"};
    const std::size_t formatIndex = m_header.format == CloudFormat::PlyAscii                ? 0
                                    : m_header.format == CloudFormat::PlyBinaryLittleEndian ? 1
                                                                                            : 2;
    m_info.formatDetail = std::string("PLY ") + kNames[formatIndex] + " 1.0, " +
                          std::to_string(vertex().count) + " vertices";
    if (binary()) {
        m_info.formatDetail += m_fixedRecords
                                   ? ", " + std::to_string(m_recordBytes) + "-byte records"
                                   : ", variable-size records (lists)";
    }
}

// One vertex line's values into `values` (float properties rounded to float, as a binary file
// would store them; list items skipped). Returns what is wrong with the line as a vertex, or
// "" when nothing is.
std::string PlyReader::parseAsciiVertex(std::string_view line, double* values) const {
    const PlyElement& element = vertex();
    const char* cursor = line.data();
    const char* end = cursor + line.size();
    std::size_t found = 0;
    for (std::size_t p = 0; p < element.properties.size(); ++p) {
        const PlyProperty& property = element.properties[p];
        const std::string_view word = nextWord(cursor, end);
        if (word.empty()) {
            return "found only " + std::to_string(found) + " values";
        }
        ++found;
        double value = 0.0;
        if (!parseDecimal(word, value)) {
            return "value '" + std::string(word) + "' for property '" + property.name +
                   "' is not a number";
        }
        if (!property.isList) {
            values[p] = property.type == PlyScalarType::Float32
                            ? static_cast<double>(static_cast<float>(value))
                            : value;
            continue;
        }
        if (!(value >= 0.0) || value != std::floor(value)) {
            return "list length '" + std::string(word) + "' for property '" + property.name +
                   "' is not a count >= 0";
        }
        for (double item = 0.0; item < value; item += 1.0) {
            if (nextWord(cursor, end).empty()) {
                return "list '" + property.name + "' has fewer than " + std::string(word) +
                       " items";
            }
            ++found;
        }
    }
    if (!nextWord(cursor, end).empty()) {
        return "found more than the " + std::to_string(found) + " values declared";
    }
    return {};
}

void PlyReader::parseAsciiVertexLines(const TextBlock& block, AsciiVertexLines& out) const {
    const std::size_t properties = vertex().properties.size();
    out.values.clear();
    out.lines.clear();
    out.stopped = false;
    TextBlockLines lines(block);
    std::string_view line;
    while (lines.next(line)) {
        if (isBlank(line)) { // a trailing empty line, say: no record
            continue;
        }
        const std::size_t at = out.values.size();
        out.values.resize(at + properties);
        std::string detail = parseAsciiVertex(line, out.values.data() + at);
        if (!detail.empty()) {
            out.values.resize(at);
            out.stopped = true;
            out.stopLine = lines.lineNumber();
            out.stopDetail = std::move(detail);
            return;
        }
        out.lines.push_back(lines.lineNumber());
    }
}

// Every vertex line, parsed on every core a block of lines at a time and visited in order on
// this thread: onVertex(values, vertexIndex, lineNumber) -> false stops. The same errors, at
// the same lines, as reading line by line: the first line that is no vertex is an error where
// a vertex is expected; after the last vertex, a data line is one only when the vertices are
// the file's last element.
template <typename OnVertex> bool PlyReader::visitAscii(OnVertex&& onVertex) {
    const PlyElement& element = vertex();
    const std::string& path = m_stream.path();
    const std::size_t properties = element.properties.size();
    // A data line after the last vertex: an error only when the vertices end the file.
    // Returns false: nothing after it is read.
    const auto afterTheVertices = [&](std::uint64_t line) {
        if (m_vertexIsLast) {
            throw InputError(InputErrorKind::CountMismatch, path, InputLocation::line(line),
                             "expected the file to end after " + std::to_string(element.count) +
                                 " vertex lines, but more data follows (is the header's vertex "
                                 "count too small?)");
        }
        return false;
    };
    std::uint64_t index = 0;    // vertices visited
    std::uint64_t lastLine = 0; // the number of the last line read
    bool stopped = false;       // by onVertex
    parseTextBlocksInParallel<AsciiVertexLines>(
        m_stream, m_vertexStart, m_vertexFirstLine,
        [this](const TextBlock& block, AsciiVertexLines& out) {
            parseAsciiVertexLines(block, out);
        },
        [&](const TextBlock& block, AsciiVertexLines& part) {
            m_asciiProgress = block.endOffset();
            lastLine = block.firstLine + block.lines - (block.bytes.back() == '\n' ? 1 : 0);
            for (std::size_t i = 0; i < part.lines.size(); ++i) {
                if (index == element.count) {
                    return afterTheVertices(part.lines[i]);
                }
                if (!onVertex(part.values.data() + i * properties, index, part.lines[i])) {
                    stopped = true;
                    return false;
                }
                ++index;
            }
            if (part.stopped) {
                if (index == element.count) {
                    return afterTheVertices(part.stopLine);
                }
                throw InputError(InputErrorKind::MalformedValue, path,
                                 InputLocation::line(part.stopLine),
                                 "vertex " + std::to_string(index) + ": " + part.stopDetail +
                                     "; expected values for: " + m_propertyNames);
            }
            return index < element.count || m_vertexIsLast;
        });
    if (stopped) {
        return false;
    }
    if (index < element.count) {
        throw InputError(InputErrorKind::Truncated, path, InputLocation::line(lastLine + 1),
                         "expected vertex " + std::to_string(index) + " of " +
                             std::to_string(element.count) + ", but the file ends");
    }
    return true;
}

// Walks records with lists: onVertex(values, vertexIndex, recordByte) -> false stops.
template <typename OnVertex> bool PlyReader::visitVariableRecords(OnVertex&& onVertex) {
    const PlyElement& element = vertex();
    PlyBodyCursor cursor(m_stream, m_vertexStart);
    std::vector<double> values(element.properties.size(), 0.0);
    for (std::uint64_t index = 0; index < element.count; ++index) {
        const std::uint64_t recordStart =
            walkRecords(cursor, element, index, m_usedProperty.data(), values.data());
        if (!onVertex(values.data(), index, recordStart)) {
            return false;
        }
    }
    if (m_vertexIsLast && cursor.offset() < m_stream.size()) {
        throw InputError(InputErrorKind::CountMismatch, m_stream.path(),
                         InputLocation::byte(cursor.offset()),
                         "expected the file to end after " + std::to_string(element.count) +
                             " vertices, but " + std::to_string(m_stream.size() - cursor.offset()) +
                             " more bytes follow (is the header's vertex count too small?)");
    }
    return true;
}

// Reads fixed-size vertex records in blocks of whole records, the next block being read on a
// helper thread meanwhile: onBlock(records, recordCount, firstVertexIndex) -> false stops.
template <typename OnBlock> bool PlyReader::visitFixedBlocks(OnBlock&& onBlock) {
    RecordBlockReader blocks(m_stream, m_vertexStart, m_recordBytes, vertex().count, kBlockBytes,
                             kFloatRecordPadding);
    RecordBlockReader::Block block;
    while (blocks.next(block)) {
        if (!onBlock(block.records, block.count, block.firstIndex)) {
            return false;
        }
    }
    return true;
}

// Any layout, value by value: onVertex(values, vertexIndex, byteOrLine) -> false stops.
// `values` is indexed by vertex property; only the properties that feed attributes are set.
template <typename OnVertex> bool PlyReader::visitVertexValues(OnVertex&& onVertex) {
    if (!binary()) {
        return visitAscii(onVertex);
    }
    if (!m_fixedRecords) {
        return visitVariableRecords(onVertex);
    }
    std::vector<double> values(vertex().properties.size(), 0.0);
    return visitFixedBlocks(
        [&](const std::uint8_t* records, std::size_t count, std::uint64_t firstIndex) {
            for (std::size_t r = 0; r < count; ++r) {
                loadUsedValues(records + r * m_recordBytes, values.data(), m_swapBytes);
                const std::uint64_t index = firstIndex + r;
                if (!onVertex(values.data(), index, m_vertexStart + index * m_recordBytes)) {
                    return false;
                }
            }
            return true;
        });
}

void PlyReader::loadUsedValues(const std::uint8_t* record, double* values, bool swapBytes) const {
    const std::vector<PlyProperty>& properties = vertex().properties;
    for (const int p : m_usedProperties) {
        values[p] = loadPlyScalar(record + m_propertyOffsets[p], properties[p].type, swapBytes);
    }
}

void PlyReader::toNativeOrder(std::uint8_t* records, std::size_t count) const {
    const auto swap = [](std::uint8_t* at, auto value, auto byteswap) {
        std::memcpy(&value, at, sizeof value);
        value = byteswap(value);
        std::memcpy(at, &value, sizeof value);
    };
    for (std::size_t r = 0; r < count; ++r, records += m_recordBytes) {
        for (const auto& [offset, bytes] : m_swapFields) {
            std::uint8_t* at = records + offset;
            if (bytes == 2) {
                swap(at, std::uint16_t{}, [](std::uint16_t v) { return __builtin_bswap16(v); });
            } else if (bytes == 4) {
                swap(at, std::uint32_t{}, [](std::uint32_t v) { return __builtin_bswap32(v); });
            } else {
                swap(at, std::uint64_t{}, [](std::uint64_t v) { return __builtin_bswap64(v); });
            }
        }
    }
}

bool PlyReader::hasType(const std::array<int, 3>& fields, PlyScalarType type) const {
    return std::all_of(fields.begin(), fields.end(),
                       [&](int p) { return vertex().properties[p].type == type; });
}

// Fixed-size records with float or double x y z: enough for the bounds pre-pass's loops,
// whatever the other properties are. A foreign-endian block is put in the host's order first
// (toNativeOrder: a pass of byte swaps, far cheaper than the value-by-value path).
bool PlyReader::fastPositions() const {
    return binary() && m_fixedRecords &&
           (hasType(m_fields.position, PlyScalarType::Float32) ||
            hasType(m_fields.position, PlyScalarType::Float64));
}

template <typename Loops>
std::optional<Loops>
PlyReader::fastTriple(bool present, const std::array<int, 3>& fields,
                      std::initializer_list<std::pair<PlyScalarType, Loops>> types) const {
    if (!present) {
        return Loops::None;
    }
    for (const auto& [type, loops] : types) {
        if (hasType(fields, type)) {
            return loops;
        }
    }
    return std::nullopt;
}

std::optional<FloatRecordLayout::Normals> PlyReader::fastNormals() const {
    using Normals = FloatRecordLayout::Normals;
    return fastTriple<Normals>(
        m_fields.hasNormals(), m_fields.normal,
        {{PlyScalarType::Float32, Normals::Float}, {PlyScalarType::Float64, Normals::Double}});
}

std::optional<FloatRecordLayout::Color> PlyReader::fastColors() const {
    using Color = FloatRecordLayout::Color;
    return fastTriple<Color>(m_fields.hasColors(), m_fields.color,
                             {{PlyScalarType::UInt8, Color::UChar},
                              {PlyScalarType::UInt16, Color::UShort},
                              {PlyScalarType::Float32, Color::Float}});
}

std::optional<FloatRecordLayout::Intensity> PlyReader::fastIntensity() const {
    using Intensity = FloatRecordLayout::Intensity;
    if (!m_fields.hasIntensity()) {
        return Intensity::None;
    }
    switch (vertex().properties[m_fields.intensity].type) {
    case PlyScalarType::UInt16:
        return Intensity::UShort;
    case PlyScalarType::Float32:
        return Intensity::Float;
    default:
        return std::nullopt;
    }
}

// The layout of ../shared/data, most scanners, CloudCompare, PDAL (double positions, ushort
// colours), Open3D (double positions and normals) and our own converter: float or double
// positions, optionally float or double normals, uchar, ushort or float colours and a ushort or
// float intensity.
bool PlyReader::fastLayout() const {
    return fastPositions() && fastNormals() && fastColors() && fastIntensity();
}

FloatRecordLayout PlyReader::floatLayout() const {
    FloatRecordLayout layout;
    layout.recordBytes = static_cast<std::size_t>(m_recordBytes);
    layout.doublePositions = hasType(m_fields.position, PlyScalarType::Float64);
    for (int axis = 0; axis < 3; ++axis) {
        layout.position[axis] = m_propertyOffsets[m_fields.position[axis]];
        if (m_fields.hasNormals()) {
            layout.normal[axis] = m_propertyOffsets[m_fields.normal[axis]];
        }
        if (m_fields.hasColors()) {
            layout.color[axis] = m_propertyOffsets[m_fields.color[axis]];
        }
    }
    // The bounds pre-pass takes this layout for its positions alone, whatever the other types;
    // the conversion loops only when fastLayout().
    layout.normalType = fastNormals().value_or(FloatRecordLayout::Normals::None);
    layout.colorType = fastColors().value_or(FloatRecordLayout::Color::None);
    layout.intensityType = fastIntensity().value_or(FloatRecordLayout::Intensity::None);
    if (m_fields.hasIntensity()) {
        layout.intensity = m_propertyOffsets[m_fields.intensity];
    }
    return layout;
}

// The pre-pass of fixed records with float or double positions: min/max of the
// stored floats, offset added once at the end: double(x) + offset is monotonic in x, so this
// equals the per-point bounds read() checks against (double positions: of x + offset, as the
// general path). The blocks are read and scanned on every core (a scan is mostly the kernel's
// copy); each thread keeps its own box, and the sample and the progress go on in file order.
void PlyReader::scanFixedRecordBounds(PrePassMonitor& monitor, Bounds& bounds,
                                      std::uint64_t& finite) {
    const FloatRecordLayout layout = floatLayout();
    const RecordArray array{m_vertexStart, m_recordBytes, vertex().count};
    const bool sampling = monitor.sampling();
    const std::uint64_t stride = monitor.sampleStride();
    std::vector<std::vector<glm::dvec3>> blockSamples(
        sampling ? static_cast<std::size_t>(recordBlockCount(array, kBlockBytes)) : 0);
    tbb::enumerable_thread_specific<FloatBox> boxes;
    tbb::enumerable_thread_specific<DoubleBounds> doubleBounds;
    scanRecordsInParallel(
        m_stream, array, kBlockBytes, kFloatRecordPadding,
        [&](std::uint8_t* records, std::size_t count, std::uint64_t firstIndex,
            std::uint64_t block) {
            if (m_swapBytes) {
                toNativeOrder(records, count);
            }
            if (layout.doublePositions) {
                extendDoubleBounds(records, count, layout, m_header.offset, doubleBounds.local());
            } else {
                extendFloatBox(records, count, layout, boxes.local());
            }
            if (!sampling) {
                return;
            }
            std::vector<glm::dvec3>& samples = blockSamples[static_cast<std::size_t>(block)];
            for (std::uint64_t i = (firstIndex + stride - 1) / stride * stride;
                 i < firstIndex + count; i += stride) {
                const glm::dvec3 source = sourcePosition(records + (i - firstIndex) * m_recordBytes,
                                                         layout, m_header.offset);
                if (SourceNormalizer::isFinite(source)) {
                    samples.push_back(source);
                }
            }
        },
        [&](std::uint64_t block, std::uint64_t endByte) {
            if (sampling) {
                std::vector<glm::dvec3> samples;
                std::swap(samples, blockSamples[static_cast<std::size_t>(block)]);
                for (const glm::dvec3& source : samples) {
                    monitor.offer(source);
                }
            }
            return monitor.reached(endByte);
        });
    FloatBox box;
    boxes.combine_each([&](const FloatBox& part) {
        for (int axis = 0; axis < 3; ++axis) {
            box.low[axis] = std::min(box.low[axis], part.low[axis]);
            box.high[axis] = std::max(box.high[axis], part.high[axis]);
        }
        box.finite += part.finite;
    });
    finite = box.finite;
    if (finite > 0) {
        for (int axis = 0; axis < 3; ++axis) {
            bounds.min[axis] = static_cast<double>(box.low[axis]) + m_header.offset[axis];
            bounds.max[axis] = static_cast<double>(box.high[axis]) + m_header.offset[axis];
        }
    }
    doubleBounds.combine_each([&](const DoubleBounds& part) {
        bounds.extend(part.box);
        finite += part.finite;
    });
}

void PlyReader::runBoundsPrePass(const OpenOptions& options) {
    Bounds bounds;
    std::uint64_t finite = 0;
    PrePassMonitor monitor(options, m_stream.path(), m_stream.size(), m_info.pointCount);
    monitor.advance(m_vertexStart);
    if (fastPositions()) {
        scanFixedRecordBounds(monitor, bounds, finite);
    } else {
        visitVertexValues([&](const double* values, std::uint64_t index,
                              std::uint64_t byteOrLine) {
            const glm::dvec3 source(values[m_fields.position[0]] + m_header.offset.x,
                                    values[m_fields.position[1]] + m_header.offset.y,
                                    values[m_fields.position[2]] + m_header.offset.z);
            if (SourceNormalizer::isFinite(source)) {
                ++finite;
                bounds.extend(source);
                if (monitor.samples(index)) {
                    monitor.offer(source);
                }
            }
            // Ascii vertices are numbered by line: the end of the block of lines they are
            // visited from stands for progress.
            return monitor.reached(binary() ? byteOrLine : m_asciiProgress);
        });
    }
    monitor.finish();
    if (finite == 0) {
        throwNoFinitePoints();
    }
    m_info.sourceBounds = bounds;
}

// convertFloatRecords does the bulk; the records it stops at (non-finite, or at or outside the
// bounds) go through addVertex, the exact rules every other layout uses.
bool PlyReader::readFastLayout(const SourceNormalizer& normalizer, BatchSink& sink,
                               ReadSummary& summary) {
    const FloatRecordLayout layout = floatLayout();
    std::optional<FloatUnitTransform> transform; // float positions' prefilter
    if (!layout.doublePositions) {
        transform.emplace(normalizer, m_info.cube, m_info.sourceBounds, m_header.offset);
    }
    std::vector<double> values(vertex().properties.size(), 0.0);
    return visitFixedBlocks(
        [&](std::uint8_t* records, std::size_t count, std::uint64_t firstIndex) {
            if (m_swapBytes) {
                toNativeOrder(records, count);
            }
            std::size_t done = 0;
            while (done < count) {
                PointBatch& batch = sink.batch();
                const std::size_t slot = sink.filled();
                const std::size_t take = std::min(count - done, sink.room());
                FloatRecordOutputs outputs;
                outputs.positions = batch.positions.data() + slot;
                outputs.normals = layout.normalType != FloatRecordLayout::Normals::None
                                      ? batch.normals.data() + slot
                                      : nullptr;
                outputs.colors = layout.colorType != FloatRecordLayout::Color::None
                                     ? batch.colors.data() + slot
                                     : nullptr;
                outputs.intensities =
                    m_fields.hasIntensity() ? batch.intensities.data() + slot : nullptr;
                const std::uint8_t* first = records + done * layout.recordBytes;
                const std::size_t converted =
                    transform ? convertFloatRecords(first, take, layout, *transform, outputs)
                              : convertDoubleRecords(first, take, layout, normalizer,
                                                     m_header.offset, outputs);
                done += converted;
                if (!sink.commit(converted)) {
                    return false;
                }
                if (converted < take) {
                    loadUsedValues(records + done * layout.recordBytes, values.data(), false);
                    const std::uint64_t byte = m_vertexStart + (firstIndex + done) * m_recordBytes;
                    if (!addVertex(values.data(), normalizer, sink, summary,
                                   InputLocation::byte(byte))) {
                        return false;
                    }
                    ++done;
                }
            }
            return true;
        });
}

bool PlyReader::addVertex(const double* values, const SourceNormalizer& normalizer, BatchSink& sink,
                          ReadSummary& summary, InputLocation where) const {
    const glm::dvec3 source(values[m_fields.position[0]] + m_header.offset.x,
                            values[m_fields.position[1]] + m_header.offset.y,
                            values[m_fields.position[2]] + m_header.offset.z);
    if (!normalizer.inBounds(source)) {
        if (!SourceNormalizer::isFinite(source)) {
            ++summary.skippedNonFinite;
            return true;
        }
        normalizer.throwOutOfBounds(m_stream.path(), where, source);
    }
    PointBatch& batch = sink.batch();
    const std::size_t slot = sink.filled();
    batch.positions[slot] = normalizer.toUnit(source);
    const std::vector<PlyProperty>& properties = vertex().properties;
    if (m_fields.hasNormals()) {
        batch.normals[slot] = glm::vec3(values[m_fields.normal[0]], values[m_fields.normal[1]],
                                        values[m_fields.normal[2]]);
    }
    if (m_fields.hasColors()) {
        for (int channel = 0; channel < 3; ++channel) {
            const int p = m_fields.color[channel];
            batch.colors[slot][channel] = plyColorChannel(values[p], properties[p].type);
        }
    }
    if (m_fields.hasIntensity()) {
        batch.intensities[slot] = plyIntensity(values[m_fields.intensity]);
    }
    return sink.commit(1);
}

void PlyReader::throwNoFinitePoints() const {
    throw InputError(InputErrorKind::NoPoints, m_stream.path(),
                     vertexLocation(binary() ? m_vertexStart : m_vertexFirstLine),
                     "all " + std::to_string(vertex().count) +
                         " vertices have non-finite (NaN or infinite) coordinates; expected at "
                         "least one finite point");
}

ReadSummary PlyReader::read(const BatchConsumer& consumer, const ReadOptions& options) {
    ReadSummary summary;
    if (options.cancel != nullptr && options.cancel->load(std::memory_order_relaxed)) {
        summary.cancelled = true;
        return summary;
    }
    const SourceNormalizer normalizer(m_info.cube, m_info.sourceBounds, 0.0);
    const std::size_t capacity = static_cast<std::size_t>(
        std::max<std::uint64_t>(1, std::min<std::uint64_t>(options.batchPoints, vertex().count)));
    BatchSink sink(m_info.attributes, capacity, options, consumer, summary);

    bool completed = false;
    if (fastLayout()) {
        completed = readFastLayout(normalizer, sink, summary);
    } else {
        completed =
            visitVertexValues([&](const double* values, std::uint64_t, std::uint64_t byteOrLine) {
                return addVertex(values, normalizer, sink, summary, vertexLocation(byteOrLine));
            });
    }
    if (!completed) {
        return summary; // cancelled
    }
    sink.finish();
    if (summary.pointsDelivered == 0) {
        throwNoFinitePoints();
    }
    return summary;
}

} // namespace

std::unique_ptr<PointReader> openPlyReader(const std::string& path, const OpenOptions& options) {
    return std::make_unique<PlyReader>(path, options);
}

} // namespace omicron
