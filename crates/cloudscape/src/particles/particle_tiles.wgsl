// A tile's list of sort keys (12 bits of quantised distance, then a 20-bit particle index),
// loaded into workgroup memory and sorted by one workgroup of TILE_LANES invocations: the screen
// tiles of particle_render.wgsl (by distance from the eye) and the light tiles of
// particle_occlusion.wgsl (by distance from the sun). The importing pass declares the lists in
// its own group (a library module binds nothing in a pass's group): `tile_counts` (atomic<u32>
// per tile: entries listed) and `tile_entries` (u32, `capacity` per tile).

// Keys a tile sorts at most (8 KiB of workgroup memory); a tile that lists more keeps the
// smallest (nearest).
const MAX_TILE_ENTRIES: u32 = 2048u;
// Invocations of a workgroup that sorts a tile.
const TILE_LANES: u32 = 256u;

var<workgroup> tile_keys: array<u32, MAX_TILE_ENTRIES>;
var<workgroup> tile_length: u32;
// A long list's keys by the top 8 bits of their distance level, to keep the nearest.
var<workgroup> tile_histogram: array<atomic<u32>, 256>;
var<workgroup> tile_cut: vec2<u32>; // (first distance bin left out or partly kept, keys kept)
var<workgroup> tile_fill: atomic<u32>;

// Loads the tile's `listed` keys into workgroup memory: all of them when they fit, otherwise the
// nearest MAX_TILE_ENTRIES (by a histogram of their distance, so the far ones a full tile drops
// are the ones its nearer particles hide). Returns how many were loaded (uniform).
fn load_tile_keys(first: u32, listed: u32, lane: u32) -> u32 {
    if listed <= MAX_TILE_ENTRIES {
        for (var i = lane; i < listed; i += TILE_LANES) {
            tile_keys[i] = tile_entries[first + i];
        }
        return listed;
    }
    atomicStore(&tile_histogram[lane], 0u);
    if lane == 0u {
        atomicStore(&tile_fill, 0u);
    }
    workgroupBarrier();
    for (var i = lane; i < listed; i += TILE_LANES) {
        atomicAdd(&tile_histogram[tile_entries[first + i] >> 24u], 1u);
    }
    workgroupBarrier();
    if lane == 0u {
        var kept = 0u;
        var bin = 0u;
        while bin < 256u && kept + atomicLoad(&tile_histogram[bin]) <= MAX_TILE_ENTRIES {
            kept += atomicLoad(&tile_histogram[bin]);
            bin++;
        }
        tile_cut = vec2<u32>(bin, kept);
    }
    let cut = workgroupUniformLoad(&tile_cut);
    for (var i = lane; i < listed; i += TILE_LANES) {
        let key = tile_entries[first + i];
        if (key >> 24u) <= cut.x {
            let slot = atomicAdd(&tile_fill, 1u);
            if slot < MAX_TILE_ENTRIES {
                tile_keys[slot] = key;
            }
        }
    }
    workgroupBarrier();
    return MAX_TILE_ENTRIES;
}

// Sorts the first `size` (a power of two) keys of the tile, ascending: a bitonic network over
// workgroup memory, each invocation taking every 256th pair.
fn sort_tile_keys(size: u32, lane: u32) {
    for (var k = 2u; k <= size; k <<= 1u) {
        for (var j = k >> 1u; j > 0u; j >>= 1u) {
            for (var i = lane; i < size; i += TILE_LANES) {
                let l = i ^ j;
                if l > i {
                    let a = tile_keys[i];
                    let b = tile_keys[l];
                    if (a > b) == ((i & k) == 0u) {
                        tile_keys[i] = b;
                        tile_keys[l] = a;
                    }
                }
            }
            workgroupBarrier();
        }
    }
}

// Loads and sorts tile `tile_index`'s keys (its list holds up to `capacity`) into `tile_keys`,
// ascending; returns how many (uniform).
fn load_sorted_tile(tile_index: u32, capacity: u32, lane: u32) -> u32 {
    if lane == 0u {
        tile_length = min(atomicLoad(&tile_counts[tile_index]), capacity);
    }
    let listed = workgroupUniformLoad(&tile_length);
    let n = load_tile_keys(tile_index * capacity, listed, lane);
    var size = 1u;
    while size < n {
        size <<= 1u;
    }
    for (var i = n + lane; i < size; i += TILE_LANES) {
        tile_keys[i] = 0xffffffffu;
    }
    workgroupBarrier();
    sort_tile_keys(size, lane);
    return n;
}
