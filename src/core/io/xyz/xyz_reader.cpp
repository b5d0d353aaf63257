// XYZ text reader (.xyz .pts .txt .csv): one point per line, numbers separated by blanks
// (spaces, tabs) or commas. The first data line's column count decides the layout:
//
//   3  x y z
//   4  x y z intensity
//   6  x y z r g b      when columns 4-6 of every data line are integer literals 0..255
//      x y z nx ny nz   otherwise (a normal is written "0.000000 0.000000 1.000000" or
//                       "0.2 0.3 0.93", a colour "0 0 255": the decision is by how the values
//                       are written, so an axis-aligned normal written "0 0 1" reads as a colour)
//   7  x y z intensity r g b   (Leica PTS)
//   9  x y z r g b nx ny nz
//
// Lines starting with '#' or "//" and blank lines are skipped anywhere. Lines before the first
// data line that are not all numbers (a CSV header "X,Y,Z") or that hold one integer (a PTS
// point count) are header lines. Every later data line must have the first one's column count.
//
// Intensities are mapped to 16 bits by the range the whole file uses: 0..65535 as written
// (rounded); -2048..2047 (Leica PTS signed 12-bit) shifted by +2048; 0..1 with fractions
// scaled by 65535. Colours in 7 and 9 columns must be integers 0..255. Non-finite normals read
// as (0, 0, 0); lines with a non-finite position are skipped and counted.
//
// Text has no header with a count or a layout, so the pre-pass always runs (it validates the
// whole file, counts the records and decides the colour/normal and intensity rules);
// OpenOptions::knownBounds only replaces the bounds it finds. Both passes parse blocks of
// lines on every core and take them in file order (io/text_blocks.hpp): the same points, the
// same first error and the same preview sample as a line-by-line read.
#include "io/xyz/xyz_reader.hpp"

#include "io/decimal_text.hpp"
#include "io/file_stream.hpp"
#include "io/input_error.hpp"
#include "io/line_reader.hpp"
#include "io/pre_pass_monitor.hpp"
#include "io/source_normalizer.hpp"
#include "io/text_blocks.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <limits>
#include <string_view>

namespace omicron {

namespace {

constexpr std::size_t kMaxColumns = 9;
// A text file with more non-numeric lines than this before any data is not a point cloud.
constexpr std::uint64_t kMaxHeaderLines = 100;
constexpr std::string_view kUtf8Bom = "\xEF\xBB\xBF";

bool isBlank(char c) {
    return c == ' ' || c == '\t' || c == '\r' || c == '\v' || c == '\f';
}

// Splits a line into fields separated by runs of blanks or by one comma with optional blanks
// around it. An empty field ("1,,2", a leading or trailing comma) comes back as "".
class FieldSplitter {
public:
    explicit FieldSplitter(std::string_view line) : m_line(line) {}

    bool next(std::string_view& field) {
        skipBlanks();
        if (m_pos == m_line.size()) {
            const bool pendingEmpty = m_afterComma;
            m_afterComma = false;
            field = {};
            return pendingEmpty;
        }
        if (m_line[m_pos] == ',') {
            ++m_pos;
            m_afterComma = true;
            field = {};
            return true;
        }
        const std::size_t start = m_pos;
        while (m_pos < m_line.size() && !isBlank(m_line[m_pos]) && m_line[m_pos] != ',') {
            ++m_pos;
        }
        field = m_line.substr(start, m_pos - start);
        skipBlanks();
        m_afterComma = m_pos < m_line.size() && m_line[m_pos] == ',';
        if (m_afterComma) {
            ++m_pos;
        }
        return true;
    }

private:
    void skipBlanks() {
        while (m_pos < m_line.size() && isBlank(m_line[m_pos])) {
            ++m_pos;
        }
    }

    std::string_view m_line;
    std::size_t m_pos = 0;
    bool m_afterComma = false;
};

bool isIntegerLiteral(std::string_view text) {
    if (!text.empty() && text.front() == '+') {
        text.remove_prefix(1);
    }
    if (text.empty()) {
        return false;
    }
    for (const char c : text) {
        if (c < '0' || c > '9') {
            return false;
        }
    }
    return true;
}

bool isColorValue(double value) {
    return value >= 0.0 && value <= 255.0 && value == std::floor(value);
}

// Shortened for error messages: a binary file read as text must not flood the terminal.
std::string quoted(std::string_view text) {
    constexpr std::size_t kShown = 40;
    std::string shown(text.substr(0, kShown));
    for (char& c : shown) {
        if (static_cast<unsigned char>(c) < 0x20 || static_cast<unsigned char>(c) >= 0x7f) {
            c = '?';
        }
    }
    return "'" + shown + (text.size() > kShown ? "...'" : "'");
}

bool isSkippedLine(std::string_view line) {
    std::size_t start = 0;
    while (start < line.size() && isBlank(line[start])) {
        ++start;
    }
    const std::string_view rest = line.substr(start);
    return rest.empty() || rest.front() == '#' || rest.substr(0, 2) == "//";
}

// The next line that holds content: a UTF-8 byte-order mark at the start of the file is
// dropped, comment and blank lines are skipped. False at the end of the file (or block).
// `Lines` is a LineReader or TextBlockLines.
template <typename Lines> bool nextContentLine(Lines& lines, std::string_view& line) {
    while (lines.next(line)) {
        if (lines.lineOffset() == 0 && line.substr(0, kUtf8Bom.size()) == kUtf8Bom) {
            line.remove_prefix(kUtf8Bom.size());
        }
        if (!isSkippedLine(line)) {
            return true;
        }
    }
    return false;
}

// One line split and parsed; never throws, so header detection can try any line.
struct Row {
    std::array<double, kMaxColumns> values{};
    std::array<std::string_view, kMaxColumns> texts{};
    std::size_t columns = 0;
    std::size_t badColumn = 0; // 1-based column of the first field that is not a number; 0: none
    std::string_view badText;

    void parse(std::string_view line) {
        columns = 0;
        badColumn = 0;
        FieldSplitter splitter(line);
        std::string_view field;
        double value = 0.0;
        while (splitter.next(field)) {
            if (!parseDecimal(field, value) && badColumn == 0) {
                badColumn = columns + 1;
                badText = field;
            }
            if (columns < kMaxColumns) {
                values[columns] = value;
                texts[columns] = field;
            }
            ++columns;
        }
    }

    bool positionFinite() const {
        return std::isfinite(values[0]) && std::isfinite(values[1]) && std::isfinite(values[2]);
    }
};

struct ColumnLayout {
    std::size_t columns = 0;
    int intensity = -1; // 0-based column of each attribute, -1 when absent
    int color = -1;
    int normal = -1;
    const char* names = "";

    AttributeSet attributes() const {
        AttributeSet set;
        if (intensity >= 0) {
            set.add(Attribute::Intensity);
        }
        if (color >= 0) {
            set.add(Attribute::Color);
        }
        if (normal >= 0) {
            set.add(Attribute::Normal);
        }
        return set;
    }
};

bool isSupportedColumnCount(std::size_t columns) {
    return columns == 3 || columns == 4 || columns == 6 || columns == 7 || columns == 9;
}

ColumnLayout layoutFor(std::size_t columns, bool sixColumnsHoldColors) {
    switch (columns) {
    case 3:
        return {3, -1, -1, -1, "x y z"};
    case 4:
        return {4, 3, -1, -1, "x y z intensity"};
    case 6:
        return sixColumnsHoldColors ? ColumnLayout{6, -1, 3, -1, "x y z r g b"}
                                    : ColumnLayout{6, -1, -1, 3, "x y z nx ny nz"};
    case 7:
        return {7, 3, 4, -1, "x y z intensity r g b"};
    default:
        return {9, -1, 3, 6, "x y z r g b nx ny nz"};
    }
}

enum class IntensityScale { AsWritten, LeicaSigned, UnitFraction };

std::uint16_t toIntensity(double value, IntensityScale scale) {
    double mapped = value;
    if (scale == IntensityScale::LeicaSigned) {
        mapped = value + 2048.0;
    } else if (scale == IntensityScale::UnitFraction) {
        mapped = value * 65535.0;
    }
    return static_cast<std::uint16_t>(std::clamp(std::round(mapped), 0.0, 65535.0));
}

// Checks shared by the pre-pass and the read: the column count and that every field is a
// number.
void checkRow(const Row& row, std::size_t expectedColumns, std::uint64_t firstDataLine,
              const std::string& path, std::uint64_t lineNumber) {
    if (row.columns != expectedColumns) {
        throw InputError(InputErrorKind::MalformedValue, path, InputLocation::line(lineNumber),
                         "expected " + std::to_string(expectedColumns) +
                             " columns (as on the first data line, line " +
                             std::to_string(firstDataLine) + "), found " +
                             std::to_string(row.columns));
    }
    if (row.badColumn != 0) {
        throw InputError(InputErrorKind::MalformedValue, path, InputLocation::line(lineNumber),
                         "column " + std::to_string(row.badColumn) + ": expected a number, found " +
                             quoted(row.badText));
    }
}

void checkColors(const Row& row, int colorColumn, const std::string& path,
                 std::uint64_t lineNumber) {
    for (int c = colorColumn; c < colorColumn + 3; ++c) {
        if (!isColorValue(row.values[c])) {
            throw InputError(InputErrorKind::MalformedValue, path, InputLocation::line(lineNumber),
                             "column " + std::to_string(c + 1) +
                                 ": expected a colour value, an integer 0..255, found " +
                                 quoted(row.texts[c]));
        }
    }
}

[[noreturn]] void throwBadIntensity(const std::string& path, std::uint64_t lineNumber, int column,
                                    double value) {
    char text[64];
    std::snprintf(text, sizeof text, "%.9g", value);
    throw InputError(InputErrorKind::MalformedValue, path, InputLocation::line(lineNumber),
                     "column " + std::to_string(column + 1) +
                         ": expected an intensity in 0..65535 (or -2048..2047 throughout, as "
                         "Leica PTS writes them), found " +
                         text);
}

// What data lines hold: a block's, then (merged in file order) the whole file's.
struct RecordTally {
    std::uint64_t records = 0;
    std::uint64_t nonFinite = 0;
    Bounds bounds;
    bool extraColumnsAreColorLiterals = true; // 6 columns: columns 4-6 all "0".."255"
    double intensityMin = std::numeric_limits<double>::infinity();
    double intensityMax = -std::numeric_limits<double>::infinity();
    std::uint64_t intensityMinLine = 0; // the first line with the smallest value
    std::uint64_t intensityMaxLine = 0;
    bool intensitiesIntegral = true;

    // Adds the tally of the lines after these.
    void merge(const RecordTally& later) {
        records += later.records;
        nonFinite += later.nonFinite;
        bounds.extend(later.bounds);
        extraColumnsAreColorLiterals =
            extraColumnsAreColorLiterals && later.extraColumnsAreColorLiterals;
        if (later.intensityMin < intensityMin) {
            intensityMin = later.intensityMin;
            intensityMinLine = later.intensityMinLine;
        }
        if (later.intensityMax > intensityMax) {
            intensityMax = later.intensityMax;
            intensityMaxLine = later.intensityMaxLine;
        }
        intensitiesIntegral = intensitiesIntegral && later.intensitiesIntegral;
    }
};

// Where the data starts, and what the whole file holds: the result of the pre-pass.
struct XyzScan : RecordTally {
    std::uint64_t dataOffset = 0; // byte offset of the first data line
    std::uint64_t dataLine = 0;   // its line number
    std::uint64_t headerLines = 0;
    std::size_t columns = 0;
    const char* separator = "space-separated";
};

// The first data line of a file: the lines before it are header lines (or comments).
void findFirstDataLine(LineReader& lines, Row& row, XyzScan& scan, const std::string& path) {
    std::string_view line;
    while (nextContentLine(lines, line)) {
        row.parse(line);
        const bool ptsCount = row.columns == 1 && isIntegerLiteral(row.texts[0]);
        if (row.badColumn == 0 && !ptsCount) {
            if (!isSupportedColumnCount(row.columns)) {
                throw InputError(
                    InputErrorKind::MalformedValue, path, InputLocation::line(lines.lineNumber()),
                    "expected 3 (x y z), 4 (x y z intensity), 6 (x y z r g b or x y z nx ny "
                    "nz), 7 (x y z intensity r g b) or 9 (x y z r g b nx ny nz) columns, found " +
                        std::to_string(row.columns));
            }
            scan.dataOffset = lines.lineOffset();
            scan.dataLine = lines.lineNumber();
            scan.columns = row.columns;
            if (line.find(',') != std::string_view::npos) {
                scan.separator = "comma-separated";
            } else if (line.find('\t') != std::string_view::npos) {
                scan.separator = "tab-separated";
            }
            return;
        }
        if (++scan.headerLines > kMaxHeaderLines) {
            throw InputError(
                InputErrorKind::MalformedValue, path, InputLocation::line(lines.lineNumber()),
                "expected a line of numbers (x y z ...) within the first " +
                    std::to_string(kMaxHeaderLines) + " non-comment lines, found " + quoted(line));
        }
    }
    throw InputError(InputErrorKind::NoPoints, path, InputLocation::none(),
                     "expected lines of numbers (x y z ...), found only comments, blank lines "
                     "or header lines");
}

// Accounts one data line (already checked by checkRow) of a file with `columns` in the
// pre-pass.
void scanRow(const Row& row, std::size_t columns, int intensityColumn, int colorColumn,
             RecordTally& scan, const std::string& path, std::uint64_t lineNumber) {
    ++scan.records;
    if (!row.positionFinite()) {
        ++scan.nonFinite;
        return;
    }
    scan.bounds.extend(glm::dvec3(row.values[0], row.values[1], row.values[2]));
    if (colorColumn >= 0) {
        checkColors(row, colorColumn, path, lineNumber);
    }
    if (columns == 6 && scan.extraColumnsAreColorLiterals) {
        for (std::size_t c = 3; c < 6; ++c) {
            if (!isIntegerLiteral(row.texts[c]) || row.values[c] > 255.0) {
                scan.extraColumnsAreColorLiterals = false;
            }
        }
    }
    if (intensityColumn >= 0) {
        const double value = row.values[intensityColumn];
        if (!std::isfinite(value)) {
            throwBadIntensity(path, lineNumber, intensityColumn, value);
        }
        if (value < scan.intensityMin) {
            scan.intensityMin = value;
            scan.intensityMinLine = lineNumber;
        }
        if (value > scan.intensityMax) {
            scan.intensityMax = value;
            scan.intensityMaxLine = lineNumber;
        }
        scan.intensitiesIntegral = scan.intensitiesIntegral && value == std::floor(value);
    }
}

// A block of data lines in the pre-pass: its tally, and every record's source position
// (NaN where not finite) when the preview samples, for the sample to be taken in file order.
struct BlockScan {
    RecordTally tally;
    std::vector<glm::dvec3> positions;
};

XyzScan scanFile(FileStream& stream, PrePassMonitor& monitor) {
    const std::string& path = stream.path();
    XyzScan scan;
    {
        Row row;
        stream.seek(0);
        LineReader lines(stream);
        monitor.advance(0);
        findFirstDataLine(lines, row, scan, path);
    }
    // The 6-column layout is not decided yet; neither candidate has a colour check here.
    const ColumnLayout layout = layoutFor(scan.columns, false);
    const int colorColumn = scan.columns == 6 ? -1 : layout.color;
    const bool sampling = monitor.sampling();
    const auto parse = [&](const TextBlock& block, BlockScan& part) {
        part.tally = {};
        part.positions.clear();
        Row row;
        TextBlockLines lines(block);
        std::string_view line;
        while (nextContentLine(lines, line)) {
            row.parse(line);
            checkRow(row, scan.columns, scan.dataLine, path, lines.lineNumber());
            scanRow(row, scan.columns, layout.intensity, colorColumn, part.tally, path,
                    lines.lineNumber());
            if (sampling) {
                part.positions.push_back(
                    row.positionFinite() ? glm::dvec3(row.values[0], row.values[1], row.values[2])
                                         : glm::dvec3(std::numeric_limits<double>::quiet_NaN()));
            }
        }
    };
    const auto merge = [&](const TextBlock& block, BlockScan& part) {
        for (std::size_t i = 0; i < part.positions.size(); ++i) {
            if (monitor.samples(scan.records + i) && !std::isnan(part.positions[i].x)) {
                monitor.offer(part.positions[i]);
            }
        }
        const bool first = scan.records == 0;
        scan.merge(part.tally);
        if (first) {
            monitor.reportNow(block.endOffset());
        } else {
            monitor.advance(block.endOffset());
        }
        return true;
    };
    parseTextBlocksInParallel<BlockScan>(stream, scan.dataOffset, scan.dataLine, parse, merge);
    monitor.finish();
    return scan;
}

IntensityScale chooseIntensityScale(const XyzScan& scan, int column, const std::string& path) {
    if (scan.intensityMin > scan.intensityMax) { // no finite point: nothing to map
        return IntensityScale::AsWritten;
    }
    if (scan.intensityMin >= 0.0 && scan.intensityMax <= 1.0 && !scan.intensitiesIntegral) {
        return IntensityScale::UnitFraction;
    }
    if (scan.intensityMin >= 0.0 && scan.intensityMax <= 65535.0) {
        return IntensityScale::AsWritten;
    }
    if (scan.intensityMin >= -2048.0 && scan.intensityMax <= 2047.0) {
        return IntensityScale::LeicaSigned;
    }
    if (scan.intensityMin < -2048.0) {
        throwBadIntensity(path, scan.intensityMinLine, column, scan.intensityMin);
    }
    throwBadIntensity(path, scan.intensityMaxLine, column, scan.intensityMax);
}

class XyzReader final : public PointReader {
public:
    XyzReader(const std::string& path, const OpenOptions& options) : m_stream(path) {
        // About 30 bytes a line, for the stride of the preview sample.
        PrePassMonitor monitor(options, path, m_stream.size(), m_stream.size() / 30);
        const XyzScan scan = scanFile(m_stream, monitor);
        if (scan.bounds.empty()) {
            throw InputError(InputErrorKind::NoPoints, path, InputLocation::none(),
                             "expected at least one point with finite x y z, found " +
                                 std::to_string(scan.records) + " lines, all non-finite");
        }
        m_layout = layoutFor(scan.columns, scan.extraColumnsAreColorLiterals);
        if (m_layout.intensity >= 0) {
            m_intensityScale = chooseIntensityScale(scan, m_layout.intensity, path);
        }
        m_dataOffset = scan.dataOffset;
        m_dataLine = scan.dataLine;

        m_info.path = path;
        m_info.format = CloudFormat::Xyz;
        m_info.formatDetail = describe(scan);
        m_info.pointCount = scan.records;
        m_info.attributes = m_layout.attributes();
        m_info.boundsFromHeader = false;
        m_info.sourceBounds = options.knownBounds ? *options.knownBounds : scan.bounds;
        m_info.cube = CubeTransform::fromBounds(m_info.sourceBounds);
    }

    ReadSummary read(const BatchConsumer& consumer, const ReadOptions& options) override {
        const std::string& path = m_info.path;
        const SourceNormalizer normalizer(m_info.cube, m_info.sourceBounds, 0.0);
        const std::size_t batchPoints = std::max<std::size_t>(options.batchPoints, 1);
        ReadSummary summary;
        PointBatch batch;
        batch.attributes = m_info.attributes;
        batch.reserve(batchPoints);
        const auto deliver = [&] {
            consumer(batch);
            summary.pointsDelivered += batch.size();
            ++summary.batches;
            batch.clear();
        };

        // Each block's points are parsed into a batch of their own, then moved into the
        // batches delivered, batchPoints at a time.
        struct BlockPoints {
            PointBatch batch;
            std::uint64_t skippedNonFinite = 0;
        };
        const auto parse = [&](const TextBlock& block, BlockPoints& part) {
            part.batch.attributes = m_info.attributes;
            part.batch.clear();
            part.skippedNonFinite = 0;
            Row row;
            TextBlockLines lines(block);
            std::string_view line;
            while (nextContentLine(lines, line)) {
                row.parse(line);
                checkRow(row, m_layout.columns, m_dataLine, path, lines.lineNumber());
                if (!row.positionFinite()) {
                    ++part.skippedNonFinite;
                    continue;
                }
                appendPoint(row, normalizer, part.batch, lines.lineNumber());
            }
        };
        const auto merge = [&](const TextBlock&, BlockPoints& part) {
            summary.skippedNonFinite += part.skippedNonFinite;
            for (std::size_t taken = 0; taken < part.batch.size();) {
                const std::size_t take =
                    std::min(part.batch.size() - taken, batchPoints - batch.size());
                batch.appendRange(part.batch, taken, taken + take);
                taken += take;
                if (batch.size() >= batchPoints) {
                    deliver();
                    if (options.cancel != nullptr && options.cancel->load()) {
                        summary.cancelled = true;
                        return false;
                    }
                }
            }
            return true;
        };
        parseTextBlocksInParallel<BlockPoints>(m_stream, m_dataOffset, m_dataLine, parse, merge);
        if (summary.cancelled) {
            return summary;
        }
        if (!batch.empty()) {
            deliver();
        }
        const std::uint64_t records = summary.pointsDelivered + summary.skippedNonFinite;
        if (records != m_info.pointCount) {
            throw InputError(InputErrorKind::CountMismatch, path, InputLocation::none(),
                             "the file changed while it was read: opening it counted " +
                                 std::to_string(m_info.pointCount) + " points, reading found " +
                                 std::to_string(records));
        }
        return summary;
    }

private:
    void appendPoint(const Row& row, const SourceNormalizer& normalizer, PointBatch& batch,
                     std::uint64_t lineNumber) const {
        const glm::dvec3 source(row.values[0], row.values[1], row.values[2]);
        if (!normalizer.inBounds(source)) {
            normalizer.throwOutOfBounds(m_info.path, InputLocation::line(lineNumber), source);
        }
        batch.positions.push_back(normalizer.toUnit(source));
        if (m_layout.intensity >= 0) {
            batch.intensities.push_back(
                toIntensity(row.values[m_layout.intensity], m_intensityScale));
        }
        if (m_layout.color >= 0) {
            checkColors(row, m_layout.color, m_info.path, lineNumber);
            const auto* rgb = &row.values[m_layout.color];
            batch.colors.emplace_back(static_cast<std::uint8_t>(rgb[0]),
                                      static_cast<std::uint8_t>(rgb[1]),
                                      static_cast<std::uint8_t>(rgb[2]));
        }
        if (m_layout.normal >= 0) {
            const auto* n = &row.values[m_layout.normal];
            const glm::dvec3 normal(n[0], n[1], n[2]);
            batch.normals.push_back(SourceNormalizer::isFinite(normal) ? glm::vec3(normal)
                                                                       : glm::vec3(0.0f));
        }
    }

    std::string describe(const XyzScan& scan) const {
        std::string detail = "XYZ text, " + std::to_string(scan.columns) + " columns (" +
                             m_layout.names + "), " + scan.separator;
        if (scan.headerLines > 0) {
            detail += ", " + std::to_string(scan.headerLines) +
                      (scan.headerLines == 1 ? " header line" : " header lines");
        }
        if (m_intensityScale == IntensityScale::LeicaSigned) {
            detail += ", intensity -2048..2047 shifted to 0..4095";
        } else if (m_intensityScale == IntensityScale::UnitFraction) {
            detail += ", intensity 0..1 scaled to 0..65535";
        }
        return detail;
    }

    FileStream m_stream;
    ColumnLayout m_layout;
    IntensityScale m_intensityScale = IntensityScale::AsWritten;
    std::uint64_t m_dataOffset = 0;
    std::uint64_t m_dataLine = 1;
};

} // namespace

std::unique_ptr<PointReader> openXyzReader(const std::string& path, const OpenOptions& options) {
    return std::make_unique<XyzReader>(path, options);
}

} // namespace omicron
