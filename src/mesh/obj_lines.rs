//! Where an OBJ file goes wrong, by line: tobj reads the file, but its
//! errors name no line ("position parse error"), and it keeps a face of one
//! or two vertices as a point or a line, which the loader drops, so a
//! mesh could lose a face silently. [`short_face`] finds such faces before
//! the load; [`locate`] walks the file as tobj does (positions, texture
//! coordinates and normals counted so far, relative indices against them,
//! indices against the whole file's counts) to find the line a failed load
//! stumbled on.

/// The first `f` line with fewer than three vertices: its number (from 1),
/// and why.
pub(super) fn short_face(text: &str) -> Option<(usize, String)> {
    text.lines().enumerate().find_map(|(i, line)| {
        let mut words = line.split_whitespace();
        (words.next() == Some("f")).then_some(())?;
        let n = words.count();
        (n < 3).then(|| {
            (
                i + 1,
                format!(
                    "a face needs 3 or more vertices, this one has {n}: `{}`",
                    line.trim()
                ),
            )
        })
    })
}

/// The first line a load fails on, if this walk finds it: its number
/// (from 1), and why.
pub(super) fn locate(text: &str) -> Option<(usize, String)> {
    let total = counts(text);
    let mut so_far = [0usize; 3];
    for (i, line) in text.lines().enumerate() {
        let mut words = line.split_whitespace();
        let key = words.next();
        let why = match key {
            Some("v") => too_few_numbers(&mut words, 3).then_some("a vertex needs 3 numbers"),
            Some("vt") => {
                too_few_numbers(&mut words, 2).then_some("a texture coordinate needs 2 numbers")
            }
            Some("vn") => too_few_numbers(&mut words, 3).then_some("a normal needs 3 numbers"),
            Some("f") | Some("l") => words.find_map(|corner| bad_corner(corner, so_far, total)),
            _ => None,
        };
        if let Some(why) = why {
            return Some((i + 1, format!("{why}: `{}`", line.trim())));
        }
        match key {
            Some("v") => so_far[0] += 1,
            Some("vt") => so_far[1] += 1,
            Some("vn") => so_far[2] += 1,
            _ => {}
        }
    }
    None
}

/// How many positions, texture coordinates and normals the file declares.
fn counts(text: &str) -> [usize; 3] {
    let mut n = [0usize; 3];
    for line in text.lines() {
        match line.split_whitespace().next() {
            Some("v") => n[0] += 1,
            Some("vt") => n[1] += 1,
            Some("vn") => n[2] += 1,
            _ => {}
        }
    }
    n
}

/// Whether fewer than `n` numbers lead the words (they are consumed).
fn too_few_numbers<'a>(words: &mut impl Iterator<Item = &'a str>, n: usize) -> bool {
    words.take(n).filter(|w| w.parse::<f64>().is_ok()).count() < n
}

/// Why a face's corner `v[/vt][/vn]` cannot be read, given the counts so
/// far (for relative indices) and in the whole file.
fn bad_corner(corner: &str, so_far: [usize; 3], total: [usize; 3]) -> Option<&'static str> {
    const WHAT: [&str; 3] = [
        "a vertex index is out of range",
        "a texture index is out of range",
        "a normal index is out of range",
    ];
    for (k, part) in corner.split('/').enumerate().take(3) {
        if part.is_empty() && k > 0 {
            continue;
        }
        let Ok(i) = part.parse::<i64>() else {
            return Some("a face's index is not a whole number");
        };
        let ok = match i {
            0 => false,
            // Counted back from the last one declared so far.
            i if i < 0 => i.unsigned_abs() <= so_far[k] as u64,
            i => i as u64 <= total[k] as u64,
        };
        if !ok {
            return Some(WHAT[k]);
        }
    }
    None
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_line_that_fails_is_found() {
        let at = |text: &str| locate(text).map(|(line, _)| line);
        assert_eq!(at("v 0 0 1\nv 1 0 1\nv 0 1 1\nf 1 2 3\n"), None);
        assert_eq!(at("v 0 0 1\nv 1 0 zero\nf 1 2 3\n"), Some(2));
        assert_eq!(at("v 0 0 1\nv 1 0\nf 1 2 3\n"), Some(2));
        assert_eq!(at("v 0 0 1\nv 1 0 1\nv 0 1 1\n\nf 1 2 7\n"), Some(5));
        assert_eq!(at("v 0 0 1\nv 1 0 1\nv 0 1 1\nf 0 1 2\n"), Some(4));
        assert_eq!(at("v 0 0 1\nv 1 0 1\nf -3 -2 -1\nv 0 1 1\n"), Some(3));
        assert_eq!(at("v 0 0 1\nv 1 0 1\nv 0 1 1\nf 1/1 2/1 3/1\n"), Some(4));
        assert_eq!(
            at("v 0 0 1\nv 1 0 1\nv 0 1 1\nvn 0 0 1\nf 1//1 2//1 3//1\n"),
            None
        );
        assert_eq!(at("v 0 0 1\nv 1 0 1\nv 0 1 1\nf 1 2 x\n"), Some(4));
        // Forward references are allowed, as tobj allows them.
        assert_eq!(at("f 1 2 3\nv 0 0 1\nv 1 0 1\nv 0 1 1\n"), None);
    }

    #[test]
    fn short_faces_are_found() {
        assert_eq!(short_face("v 0 0 1\nf 1 2 3\n"), None);
        assert_eq!(short_face("l 1 2\nf 1 2 3 4\n"), None);
        let (line, why) = short_face("v 0 0 1\nv 1 0 1\nf 1 2\n").unwrap();
        assert_eq!(line, 3);
        assert!(why.contains("has 2"), "{why}");
        assert_eq!(short_face("f\n").map(|(l, _)| l), Some(1));
    }
}
