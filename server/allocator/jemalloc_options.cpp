// jemalloc's start-up options for the programs that build maps in batches (octomap-rt build
// and bench, the octree bench), compiled into each through the octomap_rt_huge_pages CMake
// target. Not into the daemon: with these options its end-to-end p99 rose on the H200 and in
// steady state its LCM thread fell behind (datagrams dropped), as its 3 MB scan messages,
// allocated and freed hundreds of times a second, were refaulted as 2 MiB pages
// (docs/history/benchmarks-log.md, "main on the GPU machine, and jemalloc's huge pages").
// jemalloc reads this string before main (jemalloc(3), "malloc_conf"); /etc/malloc.conf and
// the MALLOC_CONF environment variable are read after it and override it, e.g.
// MALLOC_CONF=thp:default,metadata_thp:disabled turns huge pages off again.
//
// Why huge pages: OcTree's nodes and child arrays (OctoMap allocates each with `new`) are
// scattered over the heap and the octree stage hops from node to node, so far fewer TLB
// entries cover the tree on 2 MiB pages (our reading; not profiled). Measured on the H200: the
// octree stage and the voxel-list copy on campus took markedly less time with them, fr079's
// octree stage changed within its noise, and OctoMap's own time in the same process did not
// change (the same section of the log). With the kernel's THP mode `madvise` (the Debian and Ubuntu
// default) jemalloc asks for them with madvise; with `never` this is a no-op. The cost is
// memory: a 2 MiB page is backed whole once touched, a few MiB a process.

extern "C" {
// The symbol jemalloc looks up (not prefixed in Debian's libjemalloc2); a constant, read once.
// NOLINTNEXTLINE: the name and linkage are jemalloc's interface.
const char* malloc_conf = "thp:always,metadata_thp:always";
}
