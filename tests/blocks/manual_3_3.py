"""The knowledge base of the Schneider manual's worked example (chapter 3.3), transcribed
word by word from the tables printed in 3.3-3 ("Tableau de programmation complète").

Every word not listed is 0, as the manual says.  Inputs Pression (0..35) on INP1 and
Température (-50..100) on INP4, intermediate variable Débit (0..800) on VAR1, output
Ouverture (0..10) on OUT3, both with Discr = 20.
"""

ESV = {
    0: 0,
    1: 35,  # INP1 Pression
    6: -50,
    7: 100,  # INP4 Température
    22: 0,
    23: 10,
    24: 20,  # OUT3 Ouverture
    34: 0,
    35: 800,
    36: 20,  # VAR1 Débit
    46: -32188,
    47: 26978,
    48: 116,
    49: 0,  # "Débit" = H'8244' H'6962' H'0074'
}

FA = {
    # FA0 Pression faible: "fa" "ib" "le", INP1, open left, xC 3, xD 10
    0: 24934,
    1: 25193,
    2: 25964,
    3: 0,
    4: 0,
    5: -32768,
    6: -32768,
    7: 3,
    8: 10,
    # FA1 Pression moyenne
    9: 28525,
    10: 25977,
    11: 28270,
    12: 101,
    13: 0,
    14: 1,
    15: 15,
    16: 15,
    17: 25,
    # FA2 Pression forte
    18: 28518,
    19: 29810,
    20: 101,
    21: 0,
    22: 0,
    23: 18,
    24: 18,
    25: 32767,
    26: 32767,
    # FA3 Température basse (INP4 is variable 3)
    27: 24930,
    28: 29555,
    29: 101,
    30: 0,
    31: 3,
    32: -32768,
    33: -32768,
    34: -10,
    35: 20,
    # FA4 Température élevée
    36: 27778,
    37: 30309,
    38: 25986,
    39: 0,
    40: 3,
    41: 1,
    42: 30,
    43: 32767,
    44: 32767,
    # FA5 Ouverture petite (OUT3 is variable 10)
    45: 25968,
    46: 26996,
    47: 25972,
    48: 0,
    49: 10,
    50: -32768,
    51: -32768,
    52: 3,
    53: 7,
    # FA6 Ouverture grande
    54: 29287,
    55: 28257,
    56: 25956,
    57: 0,
    58: 10,
    59: 3,
    60: 7,
    61: 32767,
    62: 32767,
    # FA7 Débit faible (VAR1 is variable 14)
    63: 24934,
    64: 25193,
    65: 25964,
    66: 0,
    67: 14,
    68: -32768,
    69: -32768,
    70: 100,
    71: 200,
    # FA8 Débit moyen
    72: 28525,
    73: 25977,
    74: 110,
    75: 0,
    76: 14,
    77: 100,
    78: 200,
    79: 400,
    80: 500,
    # FA9 Débit fort
    81: 28518,
    82: 29810,
    83: 0,
    84: 0,
    85: 14,
    86: 400,
    87: 500,
    88: 32767,
    89: 32767,
    # FA10 is the first unused one
    94: 999,
}

RG = {
    0: 0,
    1: 104,
    2: 999,
    3: 999,
    4: 9,
    5: 999,  # REG0 Pression faible, Temp. NON élevée -> Débit fort
    6: 2,
    7: 999,
    8: 999,
    9: 999,
    10: 7,
    11: 999,  # REG1 Pression forte -> Débit faible
    12: 4,
    13: 1,
    14: 999,
    15: 999,
    16: 8,
    17: 999,  # REG2 Temp. élevée, Pression moyenne -> Débit moyen
    18: 7,
    19: 999,
    20: 999,
    21: 999,
    22: 5,
    23: 999,  # REG3 Débit faible -> Ouverture petite
    24: 9,
    25: 999,
    26: 999,
    27: 999,
    28: 6,
    29: 999,  # REG4 Débit fort -> Ouverture grande
    30: 999,
    31: 999,
    32: 999,
    33: 999,  # REG5 is the first unused one
}


def words(table: dict[int, int], size: int) -> tuple[int, ...]:
    return tuple(table.get(k, 0) for k in range(size))
