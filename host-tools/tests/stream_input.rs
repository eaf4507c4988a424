//! A log read from a stream (standard input through a pipe) is decoded as
//! its file would be: every unique valid block once, in time order,
//! whatever order the stream carries the blocks in.

mod analysis_support;

use analysis_support::{standard_log, stdout_of, wobblog};
use wobble_core::format::BLOCK_LEN;

/// The blocks of the log at `path`, in the order `order` gives their
/// indices, as one byte string.
fn reordered(path: &std::path::Path, order: impl Fn(usize) -> Vec<usize>) -> Vec<u8> {
    let bytes = std::fs::read(path).unwrap();
    let blocks: Vec<&[u8]> = bytes.chunks(BLOCK_LEN).collect();
    order(blocks.len())
        .into_iter()
        .flat_map(|i| blocks[i].iter().copied())
        .collect()
}

/// A block order, given the number of blocks.
type Order = dyn Fn(usize) -> Vec<usize>;

/// `wobblog ARGS /dev/stdin` with `input` piped in, which must succeed.
fn through_pipe(args: &[&str], input: &[u8]) -> String {
    stdout_of(wobblog().args(args).arg("/dev/stdin").write_stdin(input))
}

#[test]
fn a_stream_of_reordered_blocks_decodes_like_the_file_in_order() {
    let dir = tempfile::tempdir().unwrap();
    let log = dir.path().join("ride.wbl");
    standard_log(&log);
    let n = std::fs::metadata(&log).unwrap().len() as usize / BLOCK_LEN;
    assert!(n > 20, "{n} blocks");
    // Every row (the UTC column too: `decode` reads the log twice to find
    // the first sync pair, and gets the same bytes both times).
    let want = stdout_of(wobblog().arg("decode").arg(&log));
    let want_info = stdout_of(wobblog().args(["info", "--json"]).arg(&log));
    let orders: [(&str, Box<Order>); 4] = [
        ("in order", Box::new(|n| (0..n).collect())),
        ("reversed", Box::new(|n| (0..n).rev().collect())),
        (
            "neighbours swapped",
            Box::new(|n| (0..n).map(|i| (i ^ 1).min(n - 1)).collect()),
        ),
        (
            "the last block first, every block twice",
            Box::new(|n| std::iter::once(n - 1).chain(0..n).chain(0..n).collect()),
        ),
    ];
    for (what, order) in orders {
        let input = reordered(&log, order);
        assert_eq!(through_pipe(&["decode"], &input), want, "{what}");
        let info: serde_json::Value =
            serde_json::from_str(&through_pipe(&["info", "--json"], &input)).unwrap();
        let want: serde_json::Value = serde_json::from_str(&want_info).unwrap();
        for key in [
            "samples",
            "duration_s",
            "lost_blocks",
            "frames_lost",
            "first_utc",
            "segments",
        ] {
            assert_eq!(info[key], want[key], "{what}: {key}");
        }
    }
}

#[test]
fn a_stream_without_a_valid_block_is_refused_naming_it() {
    let out = wobblog()
        .args(["info", "/dev/stdin"])
        .write_stdin(b"WBLK".repeat(1000))
        .output()
        .unwrap();
    assert_eq!(out.status.code(), Some(1));
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(
        err.contains("/dev/stdin") && err.contains("no valid log block in 4000 bytes"),
        "{err}"
    );
}
