# Sweep sharding and `cloudbench merge` (docs/cli.md): two
# shards as separate processes merge into the unsharded sweep's table, perf
# histories merge with each record once, a shard set missing an index exits 3.
# Included from tests/CMakeLists.txt, where `cli` and `cli_out` are defined.
add_test(NAME Cli.ShardMerge
         COMMAND /usr/bin/python3 ${CMAKE_CURRENT_SOURCE_DIR}/check_shard.py ${cli} ${cli_out}/shard)
set_tests_properties(Cli.ShardMerge PROPERTIES PASS_REGULAR_EXPRESSION "shard and merge: ok" TIMEOUT 900)
