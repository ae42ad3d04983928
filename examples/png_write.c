/* png_write.c - PNG files encoded on every core the tool runs on (-j N).
   See tool.h for the interface.

   A PNG is its rows, each filtered (sent as its difference from the texel
   to its left, above, ...), then compressed as one zlib stream. Both steps
   split: the rows are filtered in bands, each band reading the unfiltered
   rows, and the filtered bytes are compressed in pieces of PNG_PIECE bytes,
   each piece compressed on its own (its back-references stay inside it)
   into DEFLATE blocks that end on a byte boundary, so the pieces are
   concatenated as they are into one stream. Each piece goes out as an IDAT
   chunk of its own (a PNG may cut its stream into any number of them), so
   each task also computes its chunk's CRC, and the stream's Adler-32 is
   combined from the pieces' sums. The pieces are cut by size, never by the
   number of threads: the file is the same at every -j.

   The compression is DEFLATE with matches found through hash chains (8
   candidates per position) and one step of lazy matching, each piece one
   block with Huffman codes fitted to its symbols (RFC 1951 3.2.7), stored
   as it is when that is smaller. With the fixed codes stb_image_write uses
   (RFC 1951 3.2.6), on the horse's atlases (tile, polycube, lapped --bake
   2048) and a 4224 x 4224 synth atlas, this encoder took 31 to 56 % less
   CPU on one thread than stb_image_write at its default level, for files
   0.4 to 4.7 % smaller. The fitted codes make the files about a fifth
   smaller again (a polycube's colour, normal and three data atlases: 20.0
   MB to 15.9 MB; a synth atlas of a forest floor photo 6.7 MB to 5.2 MB)
   for about 5 % more CPU in the whole command. Other row filters than
   Paeth, or longer hash chains, gained 1 to 2 % for 15 to 30 % more CPU. */

#include <stdlib.h>
#include <string.h>

#include "tool.h"

/* Bytes of filtered rows per compressed piece: small enough that an atlas
   makes many (a 4096 x 4096 RGB atlas: 192), large enough that restarting
   the 32 KiB window costs little (about 1 % of the file). */
#define PNG_PIECE (256 * 1024)
/* Rows per filtering task. */
#define PNG_BAND_ROWS 64

#define WINDOW_SIZE 32768
#define HASH_BITS 15
#define MAX_CHAIN 8             /* candidates tried per position */
#define LAZY_LIMIT 32           /* a match this long is taken without looking one byte on */
#define MIN_MATCH 3
#define MAX_MATCH 258

/* ------------------------------------------------------------------------ */
/* Checksums                                                                */
/* ------------------------------------------------------------------------ */

typedef struct crc_table {
    uint32_t entry[256];
} crc_table;

static void crc_table_init(crc_table *table)
{
    uint32_t n, k, c;
    for (n = 0; n < 256; n++) {
        for (c = n, k = 0; k < 8; k++) c = c & 1 ? 0xedb88320u ^ (c >> 1) : c >> 1;
        table->entry[n] = c;
    }
}

static uint32_t crc32_of(const crc_table *table, const unsigned char *bytes, size_t n)
{
    uint32_t c = 0xffffffffu;
    size_t i;
    for (i = 0; i < n; i++) c = table->entry[(c ^ bytes[i]) & 0xff] ^ (c >> 8);
    return c ^ 0xffffffffu;
}

#define ADLER_BASE 65521u

static uint32_t adler32_of(const unsigned char *bytes, size_t n)
{
    uint32_t s1 = 1, s2 = 0;
    while (n > 0) {
        size_t block = n < 5552 ? n : 5552, i;   /* 5552: the most bytes before s2 can overflow */
        for (i = 0; i < block; i++) {
            s1 += bytes[i];
            s2 += s1;
        }
        s1 %= ADLER_BASE;
        s2 %= ADLER_BASE;
        bytes += block;
        n -= block;
    }
    return s2 << 16 | s1;
}

/* The Adler-32 of A followed by B, from theirs and B's length. */
static uint32_t adler32_combine(uint32_t first, uint32_t second, size_t second_length)
{
    uint32_t rem = (uint32_t)(second_length % ADLER_BASE);
    uint32_t a1 = first & 0xffff, b1 = first >> 16, a2 = second & 0xffff, b2 = second >> 16;
    uint32_t s1 = (a1 + a2 + ADLER_BASE - 1) % ADLER_BASE;
    uint32_t s2 = (uint32_t)(((uint64_t)rem * a1 + b1 + b2 + ADLER_BASE - rem) % ADLER_BASE);
    return s2 << 16 | s1;
}

static void put_u32_be(unsigned char *p, uint32_t v)
{
    p[0] = (unsigned char)(v >> 24);
    p[1] = (unsigned char)(v >> 16);
    p[2] = (unsigned char)(v >> 8);
    p[3] = (unsigned char)v;
}

/* ------------------------------------------------------------------------ */
/* Row filter                                                               */
/* ------------------------------------------------------------------------ */

/* Every row goes through the Paeth filter: each byte as its difference from
   the neighbour (left, above or above-left) nearest to left + above -
   above-left. On the tool's atlases, baked textures and renders it makes
   files within 3 % of the best filter chosen row by row (as stb_image_write
   and libpng choose), at a fifth of the cost. */
static int paeth(int a, int b, int c)
{
    int p = a + b - c, pa = abs(p - a), pb = abs(p - b), pc = abs(p - c);
    return pa <= pb && pa <= pc ? a : pb <= pc ? b : c;
}

typedef struct filter_job {
    const unsigned char *pixels;
    unsigned char *filtered;    /* height rows of 1 + length bytes: the filter type, then the row */
    int length, bpp;
} filter_job;

static void filter_band(void *context, int begin, int end)
{
    const filter_job *job = (const filter_job *)context;
    int length = job->length, bpp = job->bpp, first = bpp < length ? bpp : length, y, i;
    for (y = begin; y < end; y++) {
        const unsigned char *row = job->pixels + (size_t)y * length;
        unsigned char *out = job->filtered + (size_t)y * (length + 1);
        *out++ = 4;   /* Paeth */
        if (y == 0) {
            /* Above the first row are zeros: Paeth predicts the left byte. */
            for (i = 0; i < first; i++) out[i] = row[i];
            for (; i < length; i++) out[i] = (unsigned char)(row[i] - row[i - bpp]);
        } else {
            const unsigned char *above = row - length;
            for (i = 0; i < first; i++) out[i] = (unsigned char)(row[i] - above[i]);
            for (; i < length; i++) out[i] = (unsigned char)(row[i] - paeth(row[i - bpp], above[i], above[i - bpp]));
        }
    }
}

/* ------------------------------------------------------------------------ */
/* DEFLATE with Huffman codes fitted to each piece                          */
/* ------------------------------------------------------------------------ */

typedef struct bit_writer {
    unsigned char *out;
    size_t size;
    uint32_t bits;
    int count;
} bit_writer;

/* Appends n <= 24 bits, least significant first, as DEFLATE packs them. */
static void put_bits(bit_writer *w, uint32_t value, int n)
{
    w->bits |= value << w->count;
    w->count += n;
    while (w->count >= 8) {
        w->out[w->size++] = (unsigned char)w->bits;
        w->bits >>= 8;
        w->count -= 8;
    }
}

static void align_to_byte(bit_writer *w)
{
    if (w->count > 0) put_bits(w, 0, 8 - w->count);
}

static uint32_t reverse_bits(uint32_t code, int n)
{
    uint32_t r = 0;
    int i;
    for (i = 0; i < n; i++) r |= ((code >> i) & 1) << (n - 1 - i);
    return r;
}

static const unsigned short length_base[29] = {3,  4,  5,  6,  7,  8,  9,  10, 11,  13,  15,  17,  19,  23, 27,
                                               31, 35, 43, 51, 59, 67, 83, 99, 115, 131, 163, 195, 227, 258};
static const unsigned char length_extra[29] = {0, 0, 0, 0, 0, 0, 0, 0, 1, 1, 1, 1, 2, 2, 2,
                                               2, 3, 3, 3, 3, 4, 4, 4, 4, 5, 5, 5, 5, 0};

/* The length code (0..28) of each match length 3..258, looked up once per
   match rather than searched: made once per file. */
typedef struct length_codes {
    unsigned char of[MAX_MATCH + 1];
} length_codes;

static void length_codes_init(length_codes *table)
{
    int code, length;
    memset(table, 0, sizeof *table);
    for (code = 0; code < 29; code++) {
        int last = code == 28 ? MAX_MATCH : length_base[code + 1] - 1;   /* 258 has a code of its own */
        for (length = length_base[code]; length <= last; length++) table->of[length] = (unsigned char)code;
    }
}

/* The distance code (0..29) of a distance 1..32768, and its extra bits. */
static int distance_code(int distance, int *extra_bits, uint32_t *extra)
{
    uint32_t x = (uint32_t)distance - 1;
    int high = 0;
    if (x < 4) {
        *extra_bits = 0;
        *extra = 0;
        return (int)x;
    }
    while ((x >> (high + 1)) != 0) high++;            /* the highest set bit */
    *extra_bits = high - 1;
    *extra = x & ((1u << (high - 1)) - 1);
    return 2 * high + (int)((x >> (high - 1)) & 1);
}

/* Huffman code lengths for counts[0..n) (n <= 288), none above max_bits:
   the Huffman tree, two least frequent first (ties to the lower index, so
   the file is the same on every machine); when it is deeper than max_bits,
   the counts are halved (none to zero) and the tree made again, which
   flattens it. Symbols never used get length 0; a lone symbol gets 1. */
static void code_lengths(const uint32_t *counts_in, int n, int max_bits, unsigned char *lengths)
{
    uint32_t counts[288];
    memcpy(counts, counts_in, (size_t)n * sizeof(uint32_t));
    for (;;) {
        uint64_t weight[2 * 288];
        int parent[2 * 288], symbol[288], active[2 * 288], depth[2 * 288], nleaves = 0, nactive, nodes, i, deepest = 0;
        memset(lengths, 0, (size_t)n);
        for (i = 0; i < n; i++)
            if (counts[i]) {
                symbol[nleaves] = i;
                weight[nleaves] = counts[i];
                active[nleaves] = nleaves;
                nleaves++;
            }
        if (nleaves == 0) return;
        if (nleaves == 1) {
            lengths[symbol[0]] = 1;
            return;
        }
        nactive = nodes = nleaves;
        while (nactive > 1) {
            int a = -1, b = -1, k;
            for (k = 0; k < nactive; k++) {
                int node = active[k];
                if (a < 0 || weight[node] < weight[active[a]]) {
                    b = a;
                    a = k;
                } else if (b < 0 || weight[node] < weight[active[b]]) {
                    b = k;
                }
            }
            weight[nodes] = weight[active[a]] + weight[active[b]];
            parent[active[a]] = parent[active[b]] = nodes;
            /* The new node takes a's place; the last one fills b's. */
            active[a] = nodes++;
            active[b] = active[--nactive];
        }
        depth[nodes - 1] = 0;
        for (i = nodes - 2; i >= 0; i--) depth[i] = depth[parent[i]] + 1;
        for (i = 0; i < nleaves; i++)
            if (depth[i] > deepest) deepest = depth[i];
        if (deepest <= max_bits) {
            for (i = 0; i < nleaves; i++) lengths[symbol[i]] = (unsigned char)depth[i];
            return;
        }
        for (i = 0; i < n; i++)
            if (counts[i]) counts[i] = (counts[i] >> 1) | 1u;
    }
}

/* The canonical codes of those lengths (RFC 1951 3.2.2), bit-reversed so
   that put_bits sends them first bit first. */
static void canonical_codes(const unsigned char *lengths, int n, uint32_t *codes)
{
    int count[16] = {0}, bits, i;
    uint32_t next[16], code = 0;
    for (i = 0; i < n; i++) count[lengths[i]]++;
    count[0] = 0;
    for (bits = 1; bits < 16; bits++) {
        code = (code + (uint32_t)count[bits - 1]) << 1;
        next[bits] = code;
    }
    for (i = 0; i < n; i++)
        codes[i] = lengths[i] ? reverse_bits(next[lengths[i]]++, lengths[i]) : 0;
}

static uint32_t hash3(const unsigned char *p)
{
    uint32_t v = (uint32_t)p[0] << 16 | (uint32_t)p[1] << 8 | p[2];
    return (v * 2654435761u) >> (32 - HASH_BITS);
}

/* How many bytes a and b share from the start, up to max. */
static int common_length(const unsigned char *a, const unsigned char *b, int max)
{
    int k = 0;
    while (k < max && a[k] == b[k]) k++;
    return k;
}

typedef struct matcher {
    int head[1 << HASH_BITS];   /* the last position with this hash, or -1 */
    int prev[WINDOW_SIZE];      /* the position before it with the same hash (by position mod the window) */
} matcher;

/* The longest match for data + i among the positions already inserted,
   within the window: its length (0 when under MIN_MATCH) and distance. */
static int longest_match(const matcher *m, const unsigned char *data, int n, int i, uint32_t hash, int *distance)
{
    int candidate = m->head[hash], best = MIN_MATCH - 1, chain = MAX_CHAIN, max = n - i;
    if (max > MAX_MATCH) max = MAX_MATCH;
    while (candidate >= 0 && i - candidate <= WINDOW_SIZE && chain-- > 0) {
        /* Only a candidate that beats the best so far at its last byte can beat it at all. */
        if (data[candidate + best] == data[i + best]) {
            int length = common_length(data + candidate, data + i, max);
            if (length > best) {
                best = length;
                *distance = i - candidate;
                if (length == max) break;
            }
        }
        candidate = m->prev[candidate & (WINDOW_SIZE - 1)];
    }
    return best >= MIN_MATCH ? best : 0;
}

static void insert(matcher *m, const unsigned char *data, int i)
{
    uint32_t hash = hash3(data + i);
    m->prev[i & (WINDOW_SIZE - 1)] = m->head[hash];
    m->head[hash] = i;
}

/* A parsed symbol: a literal (distance 0) or a match. */
typedef struct lz_symbol {
    unsigned short value;       /* the literal byte, or the match's length */
    unsigned short distance;    /* 1..32768 for a match */
} lz_symbol;

/* data[0..n) parsed into literals and matches (hash chains, 8 candidates
   per position, one step of lazy matching); returns how many symbols. */
static int lz_parse(matcher *m, const unsigned char *data, int n, lz_symbol *symbols)
{
    int i = 0, count = 0;
    memset(m->head, 0xff, sizeof m->head);
    while (i < n) {
        int length = 0, distance = 0;
        if (n - i >= MIN_MATCH) {
            uint32_t hash = hash3(data + i);
            length = longest_match(m, data, n, i, hash, &distance);
            m->prev[i & (WINDOW_SIZE - 1)] = m->head[hash];
            m->head[hash] = i;
            /* Lazy matching: a longer match one byte on wins over this one. */
            if (length > 0 && length < LAZY_LIMIT && n - i - 1 >= MIN_MATCH) {
                int next_distance;
                if (longest_match(m, data, n, i + 1, hash3(data + i + 1), &next_distance) > length) length = 0;
            }
        }
        if (length == 0) {
            symbols[count].value = data[i];
            symbols[count++].distance = 0;
            i++;
            continue;
        }
        symbols[count].value = (unsigned short)length;
        symbols[count++].distance = (unsigned short)distance;
        /* The matched positions join the chains too (up to the last three
           bytes, which start no match of their own). */
        {
            int end = i + length, k;
            for (k = i + 1; k < end && n - k >= MIN_MATCH; k++) insert(m, data, k);
        }
        i += length;
    }
    return count;
}

/* The order in which a dynamic block's header gives the code-length code's lengths. */
static const unsigned char length_order[19] = {16, 17, 18, 0, 8, 7, 9, 6, 10, 5, 11, 4, 12, 3, 13, 2, 14, 1, 15};

/* The literal/length and distance code lengths, run-length coded with the
   code-length alphabet (16: the previous length 3-6 times, 17: 3-10 zeros,
   18: 11-138 zeros); rle[] gets symbol | extra << 8, counts[] their use. */
static int run_lengths(const unsigned char *lengths, int n, unsigned *rle, uint32_t counts[19])
{
    int i = 0, count = 0;
    while (i < n) {
        int run = 1;
        while (i + run < n && lengths[i + run] == lengths[i]) run++;
        if (lengths[i] == 0 && run >= 3) {
            int take = run > 138 ? 138 : run;
            if (take >= 11) {
                rle[count++] = 18u | (unsigned)(take - 11) << 8;
                counts[18]++;
            } else {
                rle[count++] = 17u | (unsigned)(take - 3) << 8;
                counts[17]++;
            }
            i += take;
        } else if (lengths[i] != 0 && run >= 4) {
            int take = run - 1 > 6 ? 6 : run - 1;
            rle[count++] = lengths[i];
            counts[lengths[i]]++;
            rle[count++] = 16u | (unsigned)(take - 3) << 8;
            counts[16]++;
            i += 1 + take;
        } else {
            rle[count++] = lengths[i];
            counts[lengths[i]]++;
            i++;
        }
    }
    return count;
}

/* data[0..n) as one DEFLATE block with codes fitted to it (final: the
   stream's last), ending on a byte boundary: after a final block the bits
   are padded; after another, an empty stored block (a "sync flush") does
   it. When that would be larger than the bytes stored as they are, stored
   blocks instead. symbols: room for n. Writes at most deflate_bound(n)
   bytes; returns how many. */
static size_t deflate_bound(size_t n)
{
    return n + 5 * (n / 65535 + 1);
}

/* data[0..n) in stored blocks of at most 65535 bytes, each after a
   byte-aligned header. */
static size_t deflate_stored(const unsigned char *data, int n, int final, unsigned char *out)
{
    size_t size = 0;
    int at = 0;
    do {
        int block = n - at < 65535 ? n - at : 65535;
        out[size++] = (unsigned char)(final && at + block == n ? 1 : 0);
        out[size++] = (unsigned char)block;
        out[size++] = (unsigned char)(block >> 8);
        out[size++] = (unsigned char)~block;
        out[size++] = (unsigned char)(~block >> 8);
        memcpy(out + size, data + at, (size_t)block);
        size += (size_t)block;
        at += block;
    } while (at < n);
    return size;
}

static size_t deflate_piece(matcher *m, const length_codes *lengths, lz_symbol *symbols, const unsigned char *data,
                            int n, int final, unsigned char *out)
{
    uint32_t literal_counts[286] = {0}, distance_counts[30] = {0}, header_counts[19] = {0};
    uint32_t literal_codes[286], distance_codes[30], header_codes[19];
    unsigned char literal_lengths[286], distance_lengths[30], both[286 + 30], header_lengths[19];
    unsigned rle[286 + 30];
    const int nsymbols = lz_parse(m, data, n, symbols);
    int nliterals = 286, ndistances = 30, nrle, nheader = 19, used = 0, i;
    uint64_t bits = 0;   /* the extra bits of the matches, then the whole block */
    bit_writer w;
    for (i = 0; i < nsymbols; i++) {
        int extra_bits;
        uint32_t extra;
        if (symbols[i].distance == 0) {
            literal_counts[symbols[i].value]++;
        } else {
            const int code = lengths->of[symbols[i].value];
            literal_counts[257 + code]++;
            distance_counts[distance_code(symbols[i].distance, &extra_bits, &extra)]++;
            bits += (uint64_t)length_extra[code] + (uint64_t)extra_bits;
        }
    }
    literal_counts[256] = 1;   /* the end of the block */
    code_lengths(literal_counts, 286, 15, literal_lengths);
    code_lengths(distance_counts, 30, 15, distance_lengths);
    /* A block gives at least one distance code: without matches, one of one bit. */
    for (i = 0; i < 30; i++) used += distance_lengths[i] > 0;
    if (!used) distance_lengths[0] = 1;
    canonical_codes(literal_lengths, 286, literal_codes);
    canonical_codes(distance_lengths, 30, distance_codes);
    while (nliterals > 257 && literal_lengths[nliterals - 1] == 0) nliterals--;
    while (ndistances > 1 && distance_lengths[ndistances - 1] == 0) ndistances--;
    /* The header: both sequences of code lengths back to back, run-length
       coded, with a code of their own whose lengths come first. */
    memcpy(both, literal_lengths, (size_t)nliterals);
    memcpy(both + nliterals, distance_lengths, (size_t)ndistances);
    nrle = run_lengths(both, nliterals + ndistances, rle, header_counts);
    /* A code of one symbol is incomplete, which decoders refuse for this
       alphabet: a second symbol, never sent, completes it. */
    for (i = 0, used = 0; i < 19; i++) used += header_counts[i] > 0;
    if (used < 2) header_counts[header_counts[0] ? 1 : 0] = 1;
    code_lengths(header_counts, 19, 7, header_lengths);
    canonical_codes(header_lengths, 19, header_codes);
    while (nheader > 4 && header_lengths[length_order[nheader - 1]] == 0) nheader--;

    /* The block's size, known before it is written: when the bytes stored
       as they are take less (noise), they go out stored, so the output
       stays within deflate_bound. */
    bits += 3 + 14 + 3 * (uint64_t)nheader + 3 + 7 + 32;   /* headers, and the flush at most */
    for (i = 0; i < nrle; i++) {
        const unsigned symbol = rle[i] & 0xff;
        bits += header_lengths[symbol] + (symbol == 16 ? 2u : symbol == 17 ? 3u : symbol == 18 ? 7u : 0u);
    }
    for (i = 0; i < 286; i++) bits += (uint64_t)literal_counts[i] * literal_lengths[i];
    for (i = 0; i < 30; i++) bits += (uint64_t)distance_counts[i] * distance_lengths[i];
    if ((bits + 7) / 8 > (uint64_t)n + 5 * ((uint64_t)n / 65535 + 1)) return deflate_stored(data, n, final, out);

    w.out = out;
    w.size = 0;
    w.bits = 0;
    w.count = 0;
    put_bits(&w, final ? 1u : 0u, 1);
    put_bits(&w, 2, 2);   /* dynamic Huffman codes */
    put_bits(&w, (uint32_t)(nliterals - 257), 5);
    put_bits(&w, (uint32_t)(ndistances - 1), 5);
    put_bits(&w, (uint32_t)(nheader - 4), 4);
    for (i = 0; i < nheader; i++) put_bits(&w, header_lengths[length_order[i]], 3);
    for (i = 0; i < nrle; i++) {
        const unsigned symbol = rle[i] & 0xff, extra = rle[i] >> 8;
        put_bits(&w, header_codes[symbol], header_lengths[symbol]);
        if (symbol >= 16) put_bits(&w, extra, symbol == 16 ? 2 : symbol == 17 ? 3 : 7);
    }
    for (i = 0; i < nsymbols; i++) {
        if (symbols[i].distance == 0) {
            put_bits(&w, literal_codes[symbols[i].value], literal_lengths[symbols[i].value]);
        } else {
            const int length = symbols[i].value, code = lengths->of[length];
            int extra_bits, distance;
            uint32_t extra;
            put_bits(&w, literal_codes[257 + code], literal_lengths[257 + code]);
            put_bits(&w, (uint32_t)(length - length_base[code]), length_extra[code]);
            distance = distance_code(symbols[i].distance, &extra_bits, &extra);
            put_bits(&w, distance_codes[distance], distance_lengths[distance]);
            put_bits(&w, extra, extra_bits);
        }
    }
    put_bits(&w, literal_codes[256], literal_lengths[256]);   /* end of block */
    if (!final) put_bits(&w, 0, 3);                           /* empty stored block */
    align_to_byte(&w);
    if (!final) {
        out[w.size++] = 0;
        out[w.size++] = 0;
        out[w.size++] = 0xff;
        out[w.size++] = 0xff;
    }
    return w.size;
}

/* ------------------------------------------------------------------------ */
/* The file                                                                 */
/* ------------------------------------------------------------------------ */

typedef struct piece_job {
    const unsigned char *filtered;
    size_t size;                 /* filtered bytes in all */
    int npieces;
    const crc_table *crc;
    const length_codes *lengths;
    unsigned char **chunk;       /* per piece: a whole IDAT chunk (length, type, data, CRC), or NULL */
    size_t *chunk_size;
    uint32_t *adler;             /* per piece: the Adler-32 of its filtered bytes */
} piece_job;

static void compress_piece(void *context, int index)
{
    const piece_job *job = (const piece_job *)context;
    size_t begin = (size_t)index * PNG_PIECE;
    int n = (int)(job->size - begin < PNG_PIECE ? job->size - begin : PNG_PIECE);
    int first = index == 0, final = index == job->npieces - 1;
    matcher *m = (matcher *)malloc(sizeof *m);
    lz_symbol *symbols = (lz_symbol *)malloc((size_t)n * sizeof *symbols);
    unsigned char *chunk = (unsigned char *)malloc(8 + 2 + deflate_bound((size_t)n) + 4);
    size_t data;
    if (!m || !symbols || !chunk) {
        free(m);
        free(symbols);
        free(chunk);
        return;   /* the caller sees the NULL chunk */
    }
    memcpy(chunk + 4, "IDAT", 4);
    data = 0;
    if (first) {
        chunk[8] = 0x78;   /* zlib: DEFLATE with a 32 KiB window */
        chunk[9] = 0x5e;   /* no dictionary; the header's check bits */
        data = 2;
    }
    data += deflate_piece(m, job->lengths, symbols, job->filtered + begin, n, final, chunk + 8 + data);
    free(m);
    free(symbols);
    put_u32_be(chunk, (uint32_t)data);
    put_u32_be(chunk + 8 + data, crc32_of(job->crc, chunk + 4, 4 + data));
    job->chunk[index] = chunk;
    job->chunk_size[index] = 8 + data + 4;
    job->adler[index] = adler32_of(job->filtered + begin, (size_t)n);
}

int png_write_to_memory(const unsigned char *pixels, int width, int height, int channels, unsigned char **png,
                        size_t *png_size)
{
    static const unsigned char signature[8] = {0x89, 'P', 'N', 'G', '\r', '\n', 0x1a, '\n'};
    static const unsigned char color_type[5] = {0, 0, 4, 2, 6};   /* by channels: grey, grey+alpha, RGB, RGBA */
    const tt_executor *executor = tool_executor();
    crc_table crc;
    length_codes lengths;
    filter_job filter;
    piece_job pieces;
    unsigned char *filtered, *file = NULL, tail[12 + 4 + 12], *p;
    size_t row = (size_t)width * (size_t)channels + 1, size, total;
    uint32_t adler;
    int i, failed = 0;
    *png = NULL;
    *png_size = 0;
    if (width <= 0 || height <= 0 || channels < 1 || channels > 4) return -1;
    size = row * (size_t)height;
    filtered = (unsigned char *)malloc(size);
    memset(&pieces, 0, sizeof pieces);
    pieces.npieces = (int)((size + PNG_PIECE - 1) / PNG_PIECE);
    pieces.chunk = (unsigned char **)calloc((size_t)pieces.npieces, sizeof *pieces.chunk);
    pieces.chunk_size = (size_t *)calloc((size_t)pieces.npieces, sizeof *pieces.chunk_size);
    pieces.adler = (uint32_t *)calloc((size_t)pieces.npieces, sizeof *pieces.adler);
    if (!filtered || !pieces.chunk || !pieces.chunk_size || !pieces.adler) {
        failed = 1;
        goto done;
    }
    filter.pixels = pixels;
    filter.filtered = filtered;
    filter.length = width * channels;
    filter.bpp = channels;
    tool_parallel_ranges(executor, height, PNG_BAND_ROWS, filter_band, &filter);

    crc_table_init(&crc);
    length_codes_init(&lengths);
    pieces.filtered = filtered;
    pieces.size = size;
    pieces.crc = &crc;
    pieces.lengths = &lengths;
    tool_run_tasks(executor, pieces.npieces, compress_piece, &pieces);
    total = sizeof signature + 25;
    for (i = 0; i < pieces.npieces; i++) {
        if (!pieces.chunk[i]) failed = 1;
        total += pieces.chunk_size[i];
    }
    if (failed) goto done;
    free(filtered);   /* before the file is assembled: less memory at the peak */
    filtered = NULL;
    total += sizeof tail;
    file = (unsigned char *)malloc(total);
    if (!file) {
        failed = 1;
        goto done;
    }
    p = file;
    memcpy(p, signature, sizeof signature);
    p += sizeof signature;
    put_u32_be(p, 13);
    memcpy(p + 4, "IHDR", 4);
    put_u32_be(p + 8, (uint32_t)width);
    put_u32_be(p + 12, (uint32_t)height);
    p[16] = 8;                                  /* bits per channel */
    p[17] = color_type[channels];
    p[18] = p[19] = p[20] = 0;                  /* DEFLATE, adaptive filters, not interlaced */
    put_u32_be(p + 21, crc32_of(&crc, p + 4, 17));
    p += 25;
    adler = pieces.adler[0];
    for (i = 0; i < pieces.npieces; i++) {
        memcpy(p, pieces.chunk[i], pieces.chunk_size[i]);
        p += pieces.chunk_size[i];
        free(pieces.chunk[i]);
        pieces.chunk[i] = NULL;
        if (i > 0) {
            size_t n = i == pieces.npieces - 1 ? size - (size_t)i * PNG_PIECE : PNG_PIECE;
            adler = adler32_combine(adler, pieces.adler[i], n);
        }
    }
    /* The stream's Adler-32 in an IDAT of its own, then IEND. */
    put_u32_be(tail, 4);
    memcpy(tail + 4, "IDAT", 4);
    put_u32_be(tail + 8, adler);
    put_u32_be(tail + 12, crc32_of(&crc, tail + 4, 8));
    put_u32_be(tail + 16, 0);
    memcpy(tail + 20, "IEND", 4);
    put_u32_be(tail + 24, crc32_of(&crc, tail + 20, 4));
    memcpy(p, tail, sizeof tail);
    *png = file;
    *png_size = total;
done:
    for (i = 0; pieces.chunk && i < pieces.npieces; i++) free(pieces.chunk[i]);
    free(pieces.chunk);
    free(pieces.chunk_size);
    free(pieces.adler);
    free(filtered);
    return failed ? -1 : 0;
}
