//! Small 32-bit Arm ELF files for the tests: a header, program headers,
//! the segments' bytes, and a section for each segment that names one.

/// One `PT_LOAD` program header and its bytes.
pub struct Load {
    /// Run (virtual) address.
    pub run: u32,
    /// Load (physical) address: where the contents are stored.
    pub stored: u32,
    /// Contents (`p_filesz` bytes).
    pub data: Vec<u8>,
    /// Size in memory (`p_memsz`), at least `data.len()`.
    pub memory: u32,
    /// The name of a section that is exactly this segment's contents.
    pub section: Option<&'static str>,
}

impl Load {
    /// A segment that runs where it is stored (code, constants).
    pub fn flash(address: u32, data: Vec<u8>) -> Self {
        let memory = u32::try_from(data.len()).unwrap();
        Self {
            run: address,
            stored: address,
            data,
            memory,
            section: None,
        }
    }

    /// The same, as the contents of section `name`.
    pub fn section(self, name: &'static str) -> Self {
        Self {
            section: Some(name),
            ..self
        }
    }
}

/// Bytes `seed`, `seed + 1`, … (wrapping), `length` of them: contents
/// that tell any two places apart.
pub fn pattern(seed: u8, length: usize) -> Vec<u8> {
    (0..length)
        .map(|i| seed.wrapping_add(i.to_le_bytes()[0]))
        .collect()
}

/// An executable for Arm with `loads` as its program headers.
pub fn build(loads: &[Load]) -> Vec<u8> {
    const HEADER: u32 = 52;
    const PROGRAM_HEADER: u32 = 32;
    let with_sections: Vec<&Load> = loads.iter().filter(|l| l.section.is_some()).collect();
    // Section names: "\0" then each name and its "\0", then ".shstrtab".
    let mut strings = vec![0_u8];
    let mut string_offsets = Vec::new();
    for load in &with_sections {
        string_offsets.push(u32::try_from(strings.len()).unwrap());
        strings.extend_from_slice(load.section.unwrap_or_default().as_bytes());
        strings.push(0);
    }
    let shstrtab_name = u32::try_from(strings.len()).unwrap();
    strings.extend_from_slice(b".shstrtab\0");
    let count = u16::try_from(loads.len()).unwrap();
    let data_start = HEADER + PROGRAM_HEADER * u32::from(count);
    let data_size: u32 = loads
        .iter()
        .map(|l| u32::try_from(l.data.len()).unwrap())
        .sum();
    let strings_at = data_start + data_size;
    let sections_at = (strings_at + u32::try_from(strings.len()).unwrap()).next_multiple_of(4);
    let section_count = if with_sections.is_empty() {
        0
    } else {
        u16::try_from(with_sections.len() + 2).unwrap()
    };

    let mut file = Vec::new();
    let put16 = |file: &mut Vec<u8>, v: u16| file.extend_from_slice(&v.to_le_bytes());
    let put32 = |file: &mut Vec<u8>, v: u32| file.extend_from_slice(&v.to_le_bytes());
    file.extend_from_slice(&[0x7f, b'E', b'L', b'F', 1, 1, 1, 0]);
    file.extend_from_slice(&[0; 8]);
    put16(&mut file, 2); // e_type: executable
    put16(&mut file, 40); // e_machine: Arm
    put32(&mut file, 1); // e_version
    put32(&mut file, loads.first().map_or(0, |l| l.run) | 1); // e_entry
    put32(&mut file, HEADER); // e_phoff
    put32(
        &mut file,
        if with_sections.is_empty() {
            0
        } else {
            sections_at
        },
    ); // e_shoff
    put32(&mut file, 0x0500_0200); // e_flags: EABI 5
    put16(&mut file, 52); // e_ehsize
    put16(&mut file, 32); // e_phentsize
    put16(&mut file, count); // e_phnum
    put16(&mut file, 40); // e_shentsize
    put16(&mut file, section_count); // e_shnum
    put16(&mut file, section_count.saturating_sub(1)); // e_shstrndx: the last
    let mut offset = data_start;
    let mut offsets = Vec::new();
    for load in loads {
        let size = u32::try_from(load.data.len()).unwrap();
        put32(&mut file, 1); // p_type: PT_LOAD
        put32(&mut file, offset);
        put32(&mut file, load.run);
        put32(&mut file, load.stored);
        put32(&mut file, size);
        put32(&mut file, load.memory.max(size));
        put32(&mut file, 5); // p_flags: R + X
        put32(&mut file, 4); // p_align
        offsets.push(offset);
        offset += size;
    }
    for load in loads {
        file.extend_from_slice(&load.data);
    }
    if with_sections.is_empty() {
        return file;
    }
    file.extend_from_slice(&strings);
    file.resize(sections_at as usize, 0);
    // Section 0: all zero.
    file.extend_from_slice(&[0; 40]);
    let mut offsets_of_names = string_offsets.iter();
    for (load, offset) in loads.iter().zip(&offsets) {
        if load.section.is_none() {
            continue;
        }
        // sh_name, sh_type PROGBITS, sh_flags ALLOC, sh_addr, sh_offset,
        // sh_size, sh_link, sh_info, sh_addralign, sh_entsize.
        let size = u32::try_from(load.data.len()).unwrap();
        let name = *offsets_of_names.next().unwrap();
        words(
            &mut file,
            [name, 1, 0x2, load.run, *offset, size, 0, 0, 4, 0],
        );
    }
    let size = u32::try_from(strings.len()).unwrap();
    words(
        &mut file,
        [shstrtab_name, 3, 0, 0, strings_at, size, 0, 0, 1, 0],
    );
    file
}

/// Appends `values` as little-endian words.
fn words<const N: usize>(file: &mut Vec<u8>, values: [u32; N]) {
    for value in values {
        file.extend_from_slice(&value.to_le_bytes());
    }
}

/// A start block as embassy-rp links it for the RP2350: the markers around
/// an `IMAGE_DEF` item, the last-item word and a zero link.
pub fn start_block() -> Vec<u8> {
    [0xffff_ded3_u32, 0x1021_0142, 0x0000_01ff, 0, 0xab12_3579]
        .iter()
        .flat_map(|word| word.to_le_bytes())
        .collect()
}
