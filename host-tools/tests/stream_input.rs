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

/// Waits for `child` at most `secs` seconds; kills it and fails if it has
/// not ended by then.
fn wait_for(mut child: std::process::Child, secs: u64, what: &str) -> std::process::Output {
    let deadline = std::time::Instant::now() + std::time::Duration::from_secs(secs);
    while child.try_wait().unwrap().is_none() {
        if std::time::Instant::now() > deadline {
            let _ = child.kill();
            let _ = child.wait();
            panic!("{what}: still running after {secs} s");
        }
        std::thread::sleep(std::time::Duration::from_millis(20));
    }
    child.wait_with_output().unwrap()
}

fn spawn(args: &[&std::ffi::OsStr], stdin: std::process::Stdio) -> std::process::Child {
    std::process::Command::new(wobblog().get_program())
        .args(args)
        .stdin(stdin)
        .stdout(std::process::Stdio::piped())
        .stderr(std::process::Stdio::piped())
        .spawn()
        .unwrap()
}

#[test]
fn an_endless_stream_that_is_no_log_is_refused_early() {
    use std::io::Write;
    // 64 MiB of zeros and of `yes`: the command stops reading well before
    // the end, where it once copied all to the temporary directory (and,
    // fed forever, until the disk was full).
    for (what, pattern) in [("zeros", &b"\0"[..]), ("yes", &b"y\n"[..])] {
        let mut child = spawn(
            &["info".as_ref(), "/dev/stdin".as_ref()],
            std::process::Stdio::piped(),
        );
        let mut stdin = child.stdin.take().unwrap();
        let chunk = pattern.repeat((1 << 16) / pattern.len());
        let writer = std::thread::spawn(move || {
            let mut written = 0usize;
            while written < 64 << 20 && stdin.write_all(&chunk).is_ok() {
                written += chunk.len();
            }
            written
        });
        let out = wait_for(child, 60, what);
        let written = writer.join().unwrap();
        let err = String::from_utf8_lossy(&out.stderr);
        assert_eq!(out.status.code(), Some(1), "{what}: {err}");
        assert!(
            err.contains("/dev/stdin") && err.contains("no valid log block in the stream's first"),
            "{what}: {err}"
        );
        assert!(written < 32 << 20, "{what}: {written} bytes taken");
    }
}

#[test]
fn a_fifo_is_read_once_and_never_opened_to_compare_it() {
    // The output check once opened the FIFO and closed it again, taking
    // its writer's only reader: the command then waited forever.
    let dir = tempfile::tempdir().unwrap();
    let log = dir.path().join("RUN00001.WBL");
    standard_log(&log);
    let bytes = std::fs::read(&log).unwrap().repeat(40);
    let long = dir.path().join("RUN00002.WBL");
    std::fs::write(&long, &bytes).unwrap();
    let want = stdout_of(wobblog().arg("decode").arg(&long));
    let fifo = dir.path().join("f.fifo");
    let out_csv = dir.path().join("out.csv");
    assert!(std::process::Command::new("mkfifo")
        .arg(&fifo)
        .status()
        .unwrap()
        .success());
    for run in 0..3 {
        std::fs::write(&out_csv, b"old").unwrap();
        let writer = {
            let (fifo, bytes) = (fifo.clone(), bytes.clone());
            std::thread::spawn(move || std::fs::write(fifo, bytes).is_ok())
        };
        let child = spawn(
            &[
                "decode".as_ref(),
                fifo.as_os_str(),
                "-o".as_ref(),
                out_csv.as_os_str(),
            ],
            std::process::Stdio::null(),
        );
        let out = wait_for(child, 60, &format!("run {run}"));
        assert!(
            out.status.success(),
            "{}",
            String::from_utf8_lossy(&out.stderr)
        );
        assert!(
            writer.join().unwrap(),
            "run {run}: the writer lost its reader"
        );
        assert_eq!(
            std::fs::read_to_string(&out_csv).unwrap(),
            want,
            "run {run}"
        );
    }
}

#[test]
fn standard_input_that_is_a_socket_is_read() {
    use std::io::Write;
    let dir = tempfile::tempdir().unwrap();
    let log = dir.path().join("RUN00001.WBL");
    standard_log(&log);
    let want = stdout_of(wobblog().arg("decode").arg(&log));
    let csv = dir.path().join("out.csv");
    let (mut ours, theirs) = std::os::unix::net::UnixStream::pair().unwrap();
    let child = spawn(
        &[
            "decode".as_ref(),
            "/dev/stdin".as_ref(),
            "-o".as_ref(),
            csv.as_os_str(),
        ],
        std::process::Stdio::from(std::os::fd::OwnedFd::from(theirs)),
    );
    ours.write_all(&std::fs::read(&log).unwrap()).unwrap();
    ours.shutdown(std::net::Shutdown::Write).unwrap();
    let out = wait_for(child, 60, "socket");
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    assert_eq!(std::fs::read_to_string(&csv).unwrap(), want);
}
