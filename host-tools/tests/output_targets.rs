//! Outputs through redirections, descriptors, links, modes and odd names:
//! no target is silently replaced, split or truncated.

mod analysis_support;

use analysis_support::{steady_ride_log, wobblog};
use std::os::unix::fs::{MetadataExt, PermissionsExt};
use std::path::{Path, PathBuf};
use std::process::Command as Shell;

fn sample(dir: &Path) -> PathBuf {
    steady_ride_log(dir, 300, "ride.csv", "RUN00001.WBL").1
}

fn bin() -> PathBuf {
    PathBuf::from(wobblog().get_program())
}

/// Runs `script` in `sh` with `$W` the program and `$LOG` the log.
fn sh(dir: &Path, log: &Path, script: &str) -> std::process::Output {
    Shell::new("sh")
        .arg("-c")
        .arg(script)
        .current_dir(dir)
        .env("W", bin())
        .env("LOG", log)
        .output()
        .unwrap()
}

fn decoded(log: &Path) -> Vec<u8> {
    wobblog().arg("decode").arg(log).output().unwrap().stdout
}

#[test]
fn an_append_through_a_descriptor_name_stays_an_append() {
    let dir = tempfile::tempdir().unwrap();
    let log = sample(dir.path());
    let csv = decoded(&log);
    for (target, redirect) in [
        ("/dev/stdout", ">>"),
        ("/proc/self/fd/1", ">>"),
        ("/dev/fd/3", "3>>"),
        ("/dev/stderr", "2>>"),
    ] {
        let all = dir.path().join("all.csv");
        std::fs::write(&all, b"earlier rows\n").unwrap();
        let out = sh(
            dir.path(),
            &log,
            &format!("\"$W\" decode \"$LOG\" -o {target} {redirect} all.csv"),
        );
        assert!(
            out.status.success(),
            "{target}: {}",
            String::from_utf8_lossy(&out.stderr)
        );
        let mut expected = b"earlier rows\n".to_vec();
        expected.extend_from_slice(&csv);
        assert_eq!(std::fs::read(&all).unwrap(), expected, "{target}");
    }
}

#[test]
fn standard_output_that_is_the_input_is_refused() {
    let dir = tempfile::tempdir().unwrap();
    let log = sample(dir.path());
    let before = std::fs::read(&log).unwrap();
    let out = sh(dir.path(), &log, "\"$W\" decode \"$LOG\" >> \"$LOG\"");
    assert_eq!(out.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&out.stderr).contains("standard output is the input"));
    assert_eq!(std::fs::read(&log).unwrap(), before);
    let out = sh(
        dir.path(),
        &log,
        "\"$W\" decode \"$LOG\" -o /dev/stdout >> \"$LOG\"",
    );
    assert_eq!(out.status.code(), Some(2));
    assert_eq!(std::fs::read(&log).unwrap(), before);
}

fn decode_to(log: &Path, target: &Path, force: bool) -> std::process::Output {
    let mut cmd = wobblog();
    cmd.arg("decode").arg(log).arg("-o").arg(target);
    if force {
        cmd.arg("--force");
    }
    cmd.output().unwrap()
}

#[test]
fn a_replaced_file_keeps_its_mode_and_a_protected_one_needs_force() {
    let dir = tempfile::tempdir().unwrap();
    let log = sample(dir.path());
    let private = dir.path().join("private.csv");
    std::fs::write(&private, b"old").unwrap();
    std::fs::set_permissions(&private, std::fs::Permissions::from_mode(0o600)).unwrap();
    assert!(decode_to(&log, &private, false).status.success());
    let meta = std::fs::metadata(&private).unwrap();
    assert_eq!(meta.mode() & 0o777, 0o600);
    assert_eq!(std::fs::read(&private).unwrap(), decoded(&log));

    let locked = dir.path().join("locked.csv");
    std::fs::write(&locked, b"keep me").unwrap();
    std::fs::set_permissions(&locked, std::fs::Permissions::from_mode(0o444)).unwrap();
    let out = decode_to(&log, &locked, false);
    assert_eq!(out.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&out.stderr).contains("write-protected"));
    assert_eq!(std::fs::read(&locked).unwrap(), b"keep me");
    assert!(decode_to(&log, &locked, true).status.success());
    assert_eq!(std::fs::read(&locked).unwrap(), decoded(&log));
    assert_eq!(std::fs::metadata(&locked).unwrap().mode() & 0o777, 0o444);
}

#[test]
fn hard_links_are_not_split_without_force_and_dangling_links_stay_links() {
    let dir = tempfile::tempdir().unwrap();
    let log = sample(dir.path());
    let a = dir.path().join("a.csv");
    let b = dir.path().join("b.csv");
    std::fs::write(&a, b"shared").unwrap();
    std::fs::hard_link(&a, &b).unwrap();
    let out = decode_to(&log, &a, false);
    assert_eq!(out.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&out.stderr).contains("hard link"));
    assert_eq!(std::fs::read(&b).unwrap(), b"shared");

    let link = dir.path().join("link.csv");
    let dest = dir.path().join("not-yet.csv");
    std::os::unix::fs::symlink("not-yet.csv", &link).unwrap();
    assert!(decode_to(&log, &link, false).status.success());
    assert!(std::fs::symlink_metadata(&link)
        .unwrap()
        .file_type()
        .is_symlink());
    assert_eq!(std::fs::read(&dest).unwrap(), decoded(&log));
}

#[test]
fn a_directory_is_refused_before_the_work() {
    let dir = tempfile::tempdir().unwrap();
    let log = sample(dir.path());
    for target in [dir.path().to_path_buf(), dir.path().join("new/")] {
        let out = decode_to(&log, &target, false);
        assert_eq!(out.status.code(), Some(2), "{target:?}");
        assert!(String::from_utf8_lossy(&out.stderr).contains("is a directory"));
    }
}

#[test]
fn a_long_name_works_and_errors_never_name_the_temporary_file() {
    let dir = tempfile::tempdir().unwrap();
    let log = sample(dir.path());
    let long = dir.path().join(format!("{}.csv", "é".repeat(125)));
    assert_eq!(long.file_name().unwrap().len(), 254);
    assert!(decode_to(&log, &long, false).status.success());
    assert_eq!(std::fs::read(&long).unwrap(), decoded(&log));

    let shut = dir.path().join("shut");
    std::fs::create_dir(&shut).unwrap();
    std::fs::set_permissions(&shut, std::fs::Permissions::from_mode(0o555)).unwrap();
    let target = shut.join("out.csv");
    let out = decode_to(&log, &target, false);
    std::fs::set_permissions(&shut, std::fs::Permissions::from_mode(0o755)).unwrap();
    let stderr = String::from_utf8_lossy(&out.stderr);
    // Root may write anywhere: then the run succeeds, which is right too.
    if !out.status.success() {
        assert!(stderr.contains("out.csv"), "{stderr}");
        assert!(!stderr.contains(".tmp"), "{stderr}");
    }
}

#[test]
fn the_temporary_file_sits_beside_the_target_whatever_tmpdir_says() {
    // The target on another file system than TMPDIR where one exists
    // (a rename cannot cross file systems).
    let shm = Path::new("/dev/shm");
    let target_dir = if shm.is_dir() {
        tempfile::tempdir_in(shm).unwrap()
    } else {
        tempfile::tempdir().unwrap()
    };
    let tmp = tempfile::tempdir_in(env!("CARGO_TARGET_TMPDIR")).unwrap();
    let dir = tempfile::tempdir().unwrap();
    let log = sample(dir.path());
    let target = target_dir.path().join("out.csv");
    let out = wobblog()
        .env("TMPDIR", tmp.path())
        .arg("decode")
        .arg(&log)
        .arg("-o")
        .arg(&target)
        .output()
        .unwrap();
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    assert_eq!(std::fs::read(&target).unwrap(), decoded(&log));
    assert_eq!(std::fs::read_dir(tmp.path()).unwrap().count(), 0);
    assert_eq!(std::fs::read_dir(target_dir.path()).unwrap().count(), 1);
}

#[test]
fn a_temporary_file_left_by_a_killed_run_is_removed_by_the_next() {
    let dir = tempfile::tempdir().unwrap();
    let log = sample(dir.path());
    // A process number no system hands out (above the largest pid_max).
    let stale = dir.path().join(".out.csv.4999999.aB3dE9.tmp");
    std::fs::write(&stale, b"half a run").unwrap();
    let other = dir.path().join(".other.csv.4999999.aB3dE9.tmp");
    std::fs::write(&other, b"not ours").unwrap();
    let out = decode_to(&log, &dir.path().join("out.csv"), false);
    assert!(out.status.success());
    assert!(!stale.exists());
    assert!(other.exists(), "only the same target's leftovers go");
    assert!(String::from_utf8_lossy(&out.stderr).contains("left by an interrupted run"));
}

/// The hidden temporary files in `dir`.
fn temporaries(dir: &Path) -> Vec<String> {
    std::fs::read_dir(dir)
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .filter(|n| n.ends_with(".tmp"))
        .collect()
}

#[test]
fn a_signal_removes_the_temporary_file_and_keeps_the_old_target() {
    use std::process::Stdio;
    for signal in ["INT", "TERM", "HUP"] {
        let dir = tempfile::tempdir().unwrap();
        let target = dir.path().join("out.WBL");
        std::fs::write(&target, b"old log").unwrap();
        // `encode` waits on its input, a pipe this test holds open, with
        // its temporary output created.
        let mut child = Shell::new(bin())
            .args(["encode", "--csv", "/dev/stdin", "-o"])
            .arg(&target)
            .stdin(Stdio::piped())
            .stderr(Stdio::null())
            .spawn()
            .unwrap();
        let mut waited = 0;
        while temporaries(dir.path()).is_empty() {
            assert!(waited < 2000, "no temporary file appeared");
            std::thread::sleep(std::time::Duration::from_millis(5));
            waited += 1;
        }
        let killed = Shell::new("kill")
            .args(["-s", signal, &child.id().to_string()])
            .status()
            .unwrap();
        assert!(killed.success());
        let status = child.wait().unwrap();
        assert!(!status.success(), "{signal}");
        assert_eq!(temporaries(dir.path()), Vec::<String>::new(), "{signal}");
        assert_eq!(std::fs::read(&target).unwrap(), b"old log", "{signal}");
    }
}

#[test]
fn a_temporary_file_whose_writer_lives_is_left_alone_whatever_its_pid() {
    // A writer in another PID namespace (a container on a shared volume)
    // has a PID this process cannot see: its lock, not its PID, says it
    // lives. Once it is gone, the leftover is removed.
    let dir = tempfile::tempdir().unwrap();
    let log = sample(dir.path());
    let temp = dir.path().join(".out.csv.999999999.abcdef.tmp");
    let writer = std::fs::File::create(&temp).unwrap();
    writer.lock().unwrap();
    let out = dir.path().join("out.csv");
    assert!(decode_to(&log, &out, false).status.success());
    assert!(temp.exists(), "a live writer's file was removed");
    drop(writer);
    let again = decode_to(&log, &out, false);
    assert!(again.status.success());
    assert!(!temp.exists());
    assert!(String::from_utf8_lossy(&again.stderr).contains("left by an interrupted run"));
}
