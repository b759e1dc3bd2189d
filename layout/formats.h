// Names and numbers of every blob layout: the one list both the C++ code and
// the GLSL shaders (shaders/blob.glsl) include. Plain #defines in the common subset of C++
// and GLSL, so a layout change is one edit.
//
// Seed 000 (Rouwé 2019) §3 triangle encodings, §5 tree types.
#ifndef MESHCAST_LAYOUT_FORMATS_H
#define MESHCAST_LAYOUT_FORMATS_H

#define MC_BLOB_MAGIC 0x424C434Du   // "MCLB" little-endian
#define MC_BLOB_VERSION 2u
#define MC_BLOB_HEADER_BYTES 160u

// Per-hit outputs a trace may ask for beyond t and the triangle;
// what is not asked for is not computed and reads 0. The CPU walkers take
// them with each batch, the Vulkan methods as specialization constant 0.
#define MC_HIT_UV 1u     // barycentrics u, v of the hit in its triangle
#define MC_HIT_POINT 2u  // the hit point: org + t * dir, in float
// The query a trace answers, in the same word as the outputs:
// without a query bit the closest hit; MC_QUERY_ANY any hit in [t_min, t_max],
// the walk ending at the first triangle it takes; MC_QUERY_ALL every hit
// along the segment. Face culling rides there too: MC_CULL_BACK keeps the
// triangles whose corners run counter-clockwise seen from the ray's origin
// (det > 0 in the watertight test's sheared space), MC_CULL_FRONT the others.
#define MC_QUERY_ANY 0x100u
#define MC_QUERY_ALL 0x200u
#define MC_CULL_BACK 0x400u
#define MC_CULL_FRONT 0x800u

// Header fields as 32-bit word indices, for readers that see the blob as a
// uint array (the shaders); layout/blob_format.h checks them against BlobHeader.
#define MC_HDR_TREE_FORMAT 2u
#define MC_HDR_TRIANGLE_FORMAT 3u
#define MC_HDR_TRIANGLE_COUNT 4u
#define MC_HDR_NODE_COUNT 5u
#define MC_HDR_ROOT 9u
#define MC_HDR_BOUNDS_MIN 10u
#define MC_HDR_BOUNDS_MAX 13u
#define MC_HDR_QUANT_OFFSET 16u
#define MC_HDR_QUANT_SCALE 19u
#define MC_HDR_NODE_ORIGIN 22u
#define MC_HDR_NODE_SCALE 25u
#define MC_HDR_TREE_OFFSET 26u
#define MC_HDR_TREE_SIZE 27u
#define MC_HDR_TRIANGLE_BASE 29u
#define MC_HDR_SLOT_DIVISOR 30u
#define MC_HDR_VERTEX_OFFSET 31u
#define MC_HDR_REMAP_OFFSET 33u
#define MC_HDR_REMAP_SIZE 34u
#define MC_HDR_REMAP_BITS 35u
#define MC_HDR_REMAP_SLOTS 36u

// Tree formats (seed 000 §5).
#define MC_TREE_AABBTREE 1u            // §5.1
#define MC_TREE_QUADTREE 2u            // §5.6
#define MC_TREE_QUADTREEHALFFLOAT 3u   // §5.7
#define MC_TREE_BRUTEFORCE 4u          // §3.11: no tree, every triangle tested
#define MC_TREE_AABBTREESPLITAXIS 5u   // §5.2
#define MC_TREE_AABBTREEPNS 6u         // §5.3 and seed 002
#define MC_TREE_AABBTREECOMPRESSED 7u  // §5.4
#define MC_TREE_SKDTREE 8u             // §5.5
#define MC_TREE_STACKLESSLBVH 9u       // seed 001
#define MC_TREE_AABBLIST 10u           // §7: 256-triangle batches, one box each
#define MC_TREE_ZEROBYTE 11u           // seed 004: the index buffer is the tree
#define MC_TREE_ZEROBYTEHYBRID 12u     // seed 004's future work: AABBTree nodes over zero-byte leaves
#define MC_TREE_OCTTREECOMPRESSED 13u  // 8 children a node, 8-bit boxes on power-of-two scales

// BruteForce: the tree section is a run of records, [count (uint32)][block],
// each block holding the next brute_chunk(lanes) triangles in input order
// (fewer in the last): 16, or the codec's block width when wider (128).
#define MC_BRUTE_RECORD_BYTES 4u
#define MC_BRUTE_CHUNK 16u

// AABBList (§7, the GPU's method 2): the tree section opens with node_count
// batch entries of 32 bytes, BoundingBoxMin, BoundingBoxMax (6 floats),
// TriangleCount (1..MC_LIST_BATCH) and RecordOffset (tree-section offset of
// the batch's first record), at triangle_base the batches' records follow,
// BruteForce records of brute_chunk(lanes) triangles, batch after batch
// with nothing between them: batch b's records end where batch b + 1's
// begin. Every batch but the last holds MC_LIST_BATCH triangles, so with the
// 128-lane codecs every record is one full-size block and record k of the
// section lies at triangle_base + k * (4 + block bytes).
#define MC_LIST_BATCH 256u
#define MC_LIST_ENTRY_BYTES 32u
#define MC_LIST_MIN_AT 0u              // BoundingBoxMin's byte in the entry
#define MC_LIST_MAX_AT 12u             // BoundingBoxMax's
#define MC_LIST_COUNT_AT 24u           // TriangleCount's byte in the entry
#define MC_LIST_RECORDS_AT 28u         // RecordOffset's

// Triangle formats (seed 000 §3).
#define MC_TRI_FLOAT3 1u               // §3.1
#define MC_TRI_FLOAT3SOA4 2u           // §3.2
#define MC_TRI_INDEXED8BITPACKSOA4 3u  // §3.9
#define MC_TRI_INDEXED16 4u            // §3.6
#define MC_TRI_INDEXED32 5u            // §3.6
#define MC_TRI_INDEXED16SOA4 6u        // §3.7
#define MC_TRI_INDEXED32SOA4 7u        // §3.7
#define MC_TRI_INDEXED16BITPACKSOA4 8u // §3.8
#define MC_TRI_INDEXED32BITPACKSOA4 9u // §3.8
#define MC_TRI_FLOAT3SOA8 10u          // §3.3
#define MC_TRI_FLOAT3SOA128 11u        // §7 (GPU brute force blocks)
#define MC_TRI_BITPACKSOA4 12u         // §3.5
#define MC_TRI_BITPACKSOA128 13u       // §7
#define MC_TRI_BITPACK 14u             // §3.4
#define MC_TRI_UNCOMPRESSEDSTRIP 15u   // §3.10
#define MC_TRI_COMPRESSEDSTRIP 16u     // §3.10
#define MC_TRI_FLOAT3PAIRSOA4 18u      // seed 003: triangle pairs, the shared edge stored once
#define MC_TRI_INDEXED24 17u           // seed 004: 32-bit index words, 24 bits of vertex index, 8 of tree
#define MC_TRI_CLUSTERBITPACKSOA8 19u  // clusters of mesh-grid vertices stored once, 4-bit indices
#define MC_TRI_CLUSTERFLOAT3SOA8 20u   // the same clusters over the mesh's own float vertices

// ClusterBitPackSOA8: a leaf is a run of clusters, each
//   Origin     uint64 BitPack word: the mesh-grid codes (18 bits used of
//              each 21-bit field) of the cluster's smallest corner
//   Vertices   byte: the cluster's vertex count (1..16); bit 7: wide offsets
//   Triangles  byte: its triangle count (1..16)
//   Indices    per block of 8 triangles, corner rows 1, 2, 3 of 8 4-bit
//              vertex numbers (nibble i: triangle i of the block), a uint32 each;
//              a last block's unused lanes repeat its last triangle
//   Offsets    rows X[v], Y[v], Z[v]: uint16 each (uint32 when wide), a
//              vertex's grid code less the Origin's; an odd v pads Z by one
// A vertex decodes as fma(float(Origin + offset), quant_scale, quant_offset),
// BitPack's own decode of the same grid code, so a vertex shared by two
// clusters (or two leaves) decodes to the same bits in each. Walkers read a
// row in 4-byte words under a mask, never past the cluster.
#define MC_CLUSTER_HEADER_BYTES 10u
#define MC_CLUSTER_MAX_VERTICES 16u
#define MC_CLUSTER_MAX_TRIANGLES 16u
#define MC_CLUSTER_WIDE 0x80u
#define MC_CLUSTER_BLOCK_LANES 8u
#define MC_CLUSTER_INDEX_BLOCK_BYTES 12u

// ClusterFloat3SOA8: the same clusters with the vertices as the mesh gives
// them, nothing moved:
//   Vertices   byte: the cluster's vertex count (1..16)
//   Triangles  byte: its triangle count (1..16)
//   (2 bytes, 0: the rows below stay 4-aligned)
//   Indices    as ClusterBitPackSOA8's
//   Vertices   rows X[v], Y[v], Z[v] of float32
#define MC_CLUSTER_FLOAT_HEADER_BYTES 4u

// Zero-byte tree (seed 004). Triangle P starts a node when a walk reaches
// it: the top bytes of its three index words, low byte first, hold the
// node's 24 bits: the first child's position (21 bits, 0 for a leaf; the
// second child follows the first child's triangles) and the node's
// triangle count (3 bits, 1..7). An interior node's triangles define its
// box (each of the 6 extremes comes from one of them); a leaf's are all
// the subtree holds. With 2 triangles or more, triangle P + 1 carries the
// seed 002 sorting byte (top byte of its first word) and the shuffled flag
// (bit 0 of its second word's top byte): the node has 6 triangles and
// triangle P + j gives extreme j (min x, y, z, max x, y, z) by one corner,
// whose number (2 bits each, extreme 0 lowest) fills bits 1..6 of that top
// byte and bits 0..5 of the third word's. The seed rotates each triangle so
// its first corner gives the extreme; naming the corner instead keeps the
// caller's corner order (and so the meaning of u, v). Positions count from
// the zero-byte tree's root.
#define MC_ZBT_INDEX_MASK 0x00FFFFFFu
#define MC_ZBT_CHILD_BITS 21u
#define MC_ZBT_CHILD_MASK 0x001FFFFFu
#define MC_ZBT_MAX_TRIANGLES 0x200000u // positions in 21 bits: about 2 million
#define MC_ZBT_MAX_VERTICES 0x1000000u // vertex indices in 24 bits
#define MC_ZBT_MAX_COUNT 7u
#define MC_ZBT_FLAG_BOX_CACHE 1u       // header root word: walk with the per-thread box cache

// AABBTree node (§5.1): BoundingBoxMin (3 floats), BoundingBoxMax (3 floats),
// Properties (uint32). High bit set: a leaf whose low bits are its triangle
// count, its block right behind the node. Clear: the first child is right
// behind the node and the low bits are the second child's offset.
#define MC_AABB_NODE_BYTES 28u
#define MC_AABB_MIN_AT 0u              // BoundingBoxMin's byte in the node
#define MC_AABB_MAX_AT 12u             // BoundingBoxMax's
#define MC_AABB_PROPERTIES_AT 24u      // Properties'
#define MC_AABB_LEAF_BIT 0x80000000u
#define MC_AABB_VALUE_MASK 0x7FFFFFFFu
// AABBTreeSplitAxis (§5.2): an interior node's properties keep 2 bits of
// split axis above a 29-bit second-child offset; its first child is the one
// lower along that axis.
#define MC_SPLITAXIS_SHIFT 29u
#define MC_SPLITAXIS_OFFSET_MASK 0x1FFFFFFFu
// AABBTreePNS (§5.3, seed 002): the AABBTree node, written nodes first (depth
// first, node k at 28 k, first child k + 1) and triangle blocks after them,
// so properties address nodes by index and blocks in 4-byte units:
//   interior: bit 31 clear, 8 precomputed-node-sorting bits (23-30), second
//             child's node index (0-22: 8M nodes)
//   leaf:     bit 31 set, triangle count (26-30), block offset / 4 from the
//             triangle base (0-25: 256 MiB)
// The source kept byte offsets beside the 8 bits and ran out of them on its
// 2.26M-triangle scene; these reach about 64M triangles at 8 a leaf.
#define MC_PNS_SHIFT 23u
#define MC_PNS_INDEX_MASK 0x007FFFFFu
#define MC_PNS_COUNT_SHIFT 26u
#define MC_PNS_BLOCK_MASK 0x03FFFFFFu

// AABBTreeCompressed (§5.4): the tree section opens with
//   RootBoundsMin (3 floats), RootBoundsMax (3 floats), RootTriangleCount
// then the root node (RootTriangleCount 0) or the root's triangle block.
// A node is 12 bytes:
//   NodeBoundsMin  bits 0-20: 7-bit min x, y, z; 21-23: side bits x, y, z;
//                  24-31: left child's triangle count (0: a node)
//   NodeBoundsMax  the same for the max, with the right child's count
//   RightChildOffset (tree-section offset of the right node or block)
// The left child (node or block) follows the node. Of the two children's
// values of a component one equals the parent's; the other is stored as q,
// bound = parent.min + q * (parent.max - parent.min) / 127, with side bit 0
// when it is the left child's. q = 127 decodes to parent.max exactly.
#define MC_COMPRESSED_HEADER_BYTES 28u
#define MC_COMPRESSED_ROOT_COUNT_AT 24u  // RootTriangleCount's byte in the header
#define MC_COMPRESSED_NODE_BYTES 12u
#define MC_COMPRESSED_STEPS 127u
#define MC_COMPRESSED_SIDE_SHIFT 21u
#define MC_COMPRESSED_COUNT_SHIFT 24u

// SKDTree (§5.5): a uint32 Properties, axis in bits 30-31 (3: a leaf), the
// low 30 bits the leaf's triangle count or the right child's tree-section
// offset. An interior node is followed by LeftPlane and RightPlane (floats):
// the left child lies at or below LeftPlane, the right child at or above
// RightPlane, along the axis; the left child follows the planes, a leaf's
// block follows its Properties. The root box is the blob header's bounds.
#define MC_SKD_LEAF_AXIS 3u
#define MC_SKD_AXIS_SHIFT 30u
#define MC_SKD_VALUE_MASK 0x3FFFFFFFu
#define MC_SKD_INTERIOR_BYTES 12u
#define MC_SKD_PROPERTIES_AT 0u        // Properties' byte in the node
#define MC_SKD_LEFT_PLANE_AT 4u        // LeftPlane's (interior nodes)
#define MC_SKD_RIGHT_PLANE_AT 8u       // RightPlane's
#define MC_SKD_LEAF_BYTES 4u

// StacklessLBVH (seed 001): nodes in heap order, node n (root 1, children
// 2n and 2n+1) at tree-section offset 32 (n - 1), triangle blocks after the
// array. A node is BoundingBoxMin, BoundingBoxMax (6 floats), Count (int32:
// > 0 a leaf's triangles, < 0 minus the triangles below an interior node,
// 0 a hole no walk reaches) and Position: a leaf's block offset; for an
// interior node the 8 precomputed-node-sorting bits of seed 002 (which child
// a ray of each octant visits first; all 0 walks left first as the seed).
#define MC_LBVH_NODE_BYTES 32u
#define MC_LBVH_MIN_AT 0u              // BoundingBoxMin's byte in the node
#define MC_LBVH_MAX_AT 12u             // BoundingBoxMax's
#define MC_LBVH_COUNT_AT 24u           // Count's
#define MC_LBVH_POSITION_AT 28u        // Position's
#define MC_LBVH_MAX_DEPTH 25u          // 2^26 - 1 slots: 2 GiB of nodes

// QuadTree / QuadTreeHalfFloat child properties (§5.6): 5 bits of triangle
// count on top (0: the child is a node), 27 bits of offset below.
#define MC_QUAD_COUNT_SHIFT 27u
#define MC_QUAD_OFFSET_MASK 0x07FFFFFFu
#define MC_QUAD_MAX_COUNT 31u
#define MC_QUAD_NODE_BYTES 112u        // 24 floats + 4 uint32
#define MC_QUADHALF_NODE_BYTES 64u     // 24 half floats + 4 uint32: a cache line
// A quad node's bounds, SOA: min x of the 4 children, min y, min z, then the
// maxima; the 4 child properties follow them.
#define MC_QUAD_PROPERTIES_AT 96u      // the 4 properties' byte in a QuadTree node
#define MC_QUADHALF_PROPERTIES_AT 48u  // in a QuadTreeHalfFloat node
// Offsets are relative to the start of the tree section.

// OctTreeCompressed (the 8-wide sibling of QuadTree, named like it
// for its branching, not a spatial octree): 96-byte nodes of 8 children,
// each child box coded in 8 bits an axis against the node's frame, as
// Ylitie, Karras and Laine 2017 code CWBVH's:
//   Origin (3 floats), Exponents (3 bytes, e + 127: the float 2^e's own
//   exponent field), 1 byte unused, QLo x[8], y[8], z[8], QHi x[8], y[8],
//   z[8] (bytes), ChildProperties[8] (uint32)
//   bound = Origin[a] + q * 2^e[a], a minimum's q rounded down and a
// maximum's up. The writer picks e and Origin so that every one of the 256
// values is a float (Origin a multiple of 2^e, and 2^e no finer than the
// float spacing at the node's largest coordinate): the decode (one fma) is
// exact, so no bound depends on rounding or on the distance from the origin.
// A child property is 5 bits of triangle count (0: a node) over 27 bits of
// tree-section offset in 4-byte units (512 MiB); 0 is an unused child, whose
// QLo 255 and QHi 0 no ray enters. Children sit in the slots that order them
// front to back for the ray octant of each slot's index (CWBVH's
// assignment), which a walker without a sort may follow.
#define MC_OCT_NODE_BYTES 96u
#define MC_OCT_WIDTH 8u
#define MC_OCT_ORIGIN_AT 0u            // Origin's byte in the node
#define MC_OCT_EXPONENTS_AT 12u        // the 3 exponent bytes
#define MC_OCT_QLO_AT 16u              // QLo rows: x[8], y[8], z[8]
#define MC_OCT_QHI_AT 40u              // QHi rows
#define MC_OCT_PROPERTIES_AT 64u       // the 8 child properties
#define MC_OCT_COUNT_SHIFT 27u
#define MC_OCT_OFFSET_MASK 0x07FFFFFFu
#define MC_OCT_OFFSET_UNIT 4u
#define MC_OCT_MAX_COUNT 31u

// Triangle blocks.
#define MC_FLOAT3_TRI_BYTES 36u        // 9 floats a triangle
#define MC_SOA4_LANES 4u
#define MC_I8_HEADER_BYTES 4u          // OffsetToVertices (uint32)
#define MC_I8_BLOCK_BYTES 12u          // 4 triangles x 3 8-bit indices, SOA
#define MC_I8_WINDOW 256u              // vertices one 8-bit index reaches
#define MC_BITPACK_BITS 21u            // per component, in a uint64 (§3.4)
#define MC_BITPACK_MAX 2097151u        // 2^21 - 1

// Stack limits the walkers rely on; validation proves the tree fits them.
#define MC_MAX_DEPTH 64u

// Hit triangle for a miss.
#define MC_NO_HIT 0xFFFFFFFFu

// A scene's top level (layout/tree/top_level.h), as the Vulkan scene method
// reads the snapshot's arrays unchanged: a placed instance's record and
// its fields' bytes, an 8-wide node's (lo[3][8], hi[3][8] floats, then 8
// slot words), and what a slot holds.
#define MC_PLACED_BYTES 80u
#define MC_PLACED_ID_AT 0u
#define MC_PLACED_MESH_AT 4u
#define MC_PLACED_MASK_AT 8u
#define MC_PLACED_FLIP_FACING_AT 12u
#define MC_PLACED_TO_LOCAL_AT 16u      // 9 floats, row-major
#define MC_PLACED_TRANSLATION_AT 56u   // 3 doubles
#define MC_TOP_NODE_BYTES 224u
#define MC_TOP_LO_AT 0u
#define MC_TOP_HI_AT 96u
#define MC_TOP_SLOT_AT 192u
#define MC_TOP_WIDTH 8u
#define MC_TOP_INSTANCE 0x80000000u    // | an index into the placed records
#define MC_TOP_EMPTY 0xFFFFFFFFu
// The depth a walk's stack is sized for: median splits of fewer than 2^31
// instances (Scene's limit) are at most 31 levels deep, and a wide node
// leaves at most 7 entries behind a level (stack: 7 * depth + 8, the 8 a
// node's test writes past the top).
#define MC_TOP_MAX_DEPTH 32u
// The pad every top-level box is widened by, of the ray origin's farthest
// distance from the scene's box (cpu/scene_trace.cpp says why).
#define MC_TOP_BOX_SLACK 1.52587890625e-05  // 2^-16

#endif
