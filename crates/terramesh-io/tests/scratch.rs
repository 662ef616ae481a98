//! What a signal handler's `scratch::remove_all` does to files being written: their temporary
//! files go, the targets stay as they were. (Its own test binary: `remove_all` is global.)

use std::io::Write;

use terramesh_io::output::Output;
use terramesh_io::scratch;

#[test]
fn remove_all_takes_the_temporary_files_of_outputs_and_leaves_the_targets() {
    let dir = tempfile::tempdir().unwrap();
    let old = dir.path().join("old.csv");
    std::fs::write(&old, "precious").unwrap();
    let mut a = Output::create(Some(&old)).unwrap();
    a.write_all(b"half of a new").unwrap();
    a.flush().unwrap();
    let mut b = Output::create(Some(&dir.path().join("new.csv"))).unwrap();
    b.write_all(b"half").unwrap();
    let committed = dir.path().join("done.csv");
    let mut c = Output::create(Some(&committed)).unwrap();
    c.write_all(b"whole").unwrap();
    c.commit().unwrap();
    assert_eq!(std::fs::read_dir(dir.path()).unwrap().count(), 4);
    // The two outputs still being written are listed; the committed one is not.
    assert_eq!(scratch::remove_all(), 2);
    let mut left: Vec<String> = std::fs::read_dir(dir.path())
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .collect();
    left.sort();
    assert_eq!(left, ["done.csv", "old.csv"]);
    assert_eq!(std::fs::read_to_string(&old).unwrap(), "precious");
    assert_eq!(std::fs::read_to_string(&committed).unwrap(), "whole");
    // A commit after the handler ran fails and creates nothing.
    assert!(a.commit().is_err());
    assert_eq!(std::fs::read_to_string(&old).unwrap(), "precious");
    drop(b);
    assert_eq!(scratch::remove_all(), 0);
}
