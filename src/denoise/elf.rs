//! A check of an ELF shared library's length before `dlopen` maps it: a file cut short (a
//! broken download or copy) is mapped without complaint and then faults with SIGBUS when the
//! loader touches the missing pages, so it has to be refused first.

use std::fs::File;
use std::os::unix::fs::FileExt;
use std::path::Path;

/// `Err` with the reason when `path` is an ELF file shorter than its headers say (its
/// segments' or section headers' ends beyond its length). Files that are not ELF, or cannot
/// be read, pass: the loader reports those itself.
pub fn check_length(path: &Path) -> Result<(), String> {
    let Ok(file) = File::open(path) else {
        return Ok(());
    };
    let Ok(len) = file.metadata().map(|m| m.len()) else {
        return Ok(());
    };
    let mut ident = [0u8; 64];
    if file.read_exact_at(&mut ident, 0).is_err() || &ident[..4] != b"\x7fELF" {
        return Ok(());
    }
    let wide = ident[4] == 2;
    let big = ident[5] == 2;
    let int = |b: &[u8]| -> u64 {
        let mut v = 0u64;
        for i in 0..b.len() {
            let byte = if big { b[i] } else { b[b.len() - 1 - i] };
            v = v << 8 | byte as u64;
        }
        v
    };
    // Offsets of e_phoff, e_shoff, e_phentsize, e_phnum, e_shentsize, e_shnum (ELF64, ELF32),
    // and of p_offset, p_filesz in a program header.
    let (phoff, shoff, sizes, word, p_off, p_size) = if wide {
        (
            int(&ident[0x20..0x28]),
            int(&ident[0x28..0x30]),
            0x36,
            8,
            0x08,
            0x20,
        )
    } else {
        (
            int(&ident[0x1c..0x20]),
            int(&ident[0x20..0x24]),
            0x2a,
            4,
            0x04,
            0x10,
        )
    };
    let field = |i: usize| int(&ident[sizes + 2 * i..sizes + 2 * i + 2]);
    let (phentsize, phnum, shentsize, shnum) = (field(0), field(1), field(2), field(3));
    let mut needed = shoff.saturating_add(shentsize.saturating_mul(shnum));
    needed = needed.max(phoff.saturating_add(phentsize.saturating_mul(phnum)));
    if needed <= len && phentsize >= p_size + word {
        let mut ph = vec![0u8; (phentsize * phnum) as usize];
        if file.read_exact_at(&mut ph, phoff).is_ok() {
            for h in ph.chunks_exact(phentsize as usize) {
                let off = int(&h[p_off as usize..(p_off + word) as usize]);
                let size = int(&h[p_size as usize..(p_size + word) as usize]);
                needed = needed.max(off.saturating_add(size));
            }
        }
    }
    if needed > len {
        return Err(format!(
            "the file is truncated ({len} bytes, its ELF headers need {needed})"
        ));
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn whole_elf_files_pass_and_cut_ones_fail() {
        let dir = std::env::temp_dir().join(format!("tesela-elf-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        // This test's own executable is a complete ELF file.
        let exe = std::env::current_exe().unwrap();
        assert_eq!(check_length(&exe), Ok(()));
        let bytes = std::fs::read(&exe).unwrap();
        for cut in [bytes.len() - 1, bytes.len() / 2, 100] {
            let p = dir.join(format!("cut{cut}"));
            std::fs::write(&p, &bytes[..cut]).unwrap();
            let e = check_length(&p).unwrap_err();
            assert!(e.contains(&format!("({cut} bytes")), "{e}");
        }
        // Not ELF, or absent: left to the loader.
        let text = dir.join("text.so");
        std::fs::write(&text, b"not a library").unwrap();
        assert_eq!(check_length(&text), Ok(()));
        assert_eq!(check_length(&dir.join("absent.so")), Ok(()));
        let _ = std::fs::remove_dir_all(&dir);
    }
}
