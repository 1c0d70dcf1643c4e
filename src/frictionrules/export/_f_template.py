"""The return mapping in fixed-form Fortran 77: the text the Abaqus targets write after the
law's local subroutines.

Line for line the algorithm of the compiled return mapping (``contact/_kernel_template.py``)
and of the C target (``_c_template.py``): limit check, Newton on the dimensionless residual
with a backtracking line search, apex of a cone, consistent tangent. ``@P@`` is replaced by the
prefix of the law's names and ``@PARAMS@`` by the PARAMETER statements of the layout (``NQ``,
``NQS``, ``M``, ``NSIZE``, ``ICLIP``, ``KAPPA``, the offsets ``OFF*``). Every name is declared
(``IMPLICIT NONE``); no line passes column 72.
"""

CORE = """\
C ----------------------------------------------------------------------
C The law's quantities at (T1, T2, N, Q) into W, made finite at kinks.
      SUBROUTINE @P@EV(S0, S1, S2, Q, P, W, LEVEL)
      IMPLICIT NONE
@PARAMS@
      DOUBLE PRECISION S0, S1, S2, Q(NQS), P(*), W(*)
      INTEGER LEVEL, K, LAST, J
      DOUBLE PRECISION SN, R, BEST, A
      SN = S2
      IF (ICLIP .EQ. 1) SN = MAX(S2, 0.0D0)
      LAST = NSIZE
      IF (LEVEL .EQ. 0) THEN
         CALL @P@LF(S0, S1, SN, Q, P, W)
         LAST = 1
      ELSE IF (LEVEL .EQ. 1) THEN
         CALL @P@L1(S0, S1, SN, Q, P, W)
      ELSE
         CALL @P@L2(S0, S1, SN, Q, P, W)
      END IF
      DO 10 K = 2, LAST
         IF (.NOT. (ABS(W(K)) .LE. HUGE(1.0D0))) W(K) = 0.0D0
   10 CONTINUE
      IF (.NOT. (ABS(W(1)) .LE. HUGE(1.0D0))) THEN
         R = 1.0D-9*(SQRT(S0*S0 + S1*S1) + ABS(SN)) + 1.0D-300
         BEST = -HUGE(1.0D0)
         DO 20 J = 0, 7
            A = 0.25D0*3.14159265358979323846D0*J
            CALL @P@LF(S0 + R*COS(A), S1 + R*SIN(A), SN, Q, P, W)
            IF (W(1) .GT. BEST) BEST = W(1)
   20    CONTINUE
         W(1) = BEST
      END IF
      RETURN
      END
C ----------------------------------------------------------------------
C Scaled backward-Euler residual at X = (SIGMA, Q, DLAM) into R; its
C norm (1D300 where a component passes 1D150: the line search rejects).
      DOUBLE PRECISION FUNCTION @P@RS(W, X, STR, QN, DV, ROWS, R)
      IMPLICIT NONE
@PARAMS@
      DOUBLE PRECISION W(*), X(M), STR(3), QN(NQS), DV(3)
      DOUBLE PRECISION ROWS(M), R(M), ACC
      INTEGER A, J, NQV
      NQV = NQ
      @P@RS = 1.0D300
      ACC = 0.0D0
      DO 10 A = 1, 3
         R(A) = (X(A) - STR(A) + X(M)*DV(A)*W(OFFDG + A))*ROWS(A)
         IF (.NOT. (ABS(R(A)) .LT. 1.0D150)) RETURN
         ACC = ACC + R(A)*R(A)
   10 CONTINUE
      DO 20 J = 1, NQV
         R(3 + J) = (X(3 + J) - QN(J) - X(M)*W(OFFH + J))*ROWS(3 + J)
         IF (.NOT. (ABS(R(3 + J)) .LT. 1.0D150)) RETURN
         ACC = ACC + R(3 + J)**2
   20 CONTINUE
      R(M) = W(1)*ROWS(M)
      IF (.NOT. (ABS(R(M)) .LT. 1.0D150)) RETURN
      ACC = ACC + R(M)*R(M)
      @P@RS = SQRT(ACC)
      RETURN
      END
C ----------------------------------------------------------------------
C Newton Jacobian of the residual in (SIGMA, Q, DLAM), unscaled.
      SUBROUTINE @P@JA(W, ALAM, DV, AJ)
      IMPLICIT NONE
@PARAMS@
      DOUBLE PRECISION W(*), ALAM, DV(3), AJ(M, M)
      INTEGER A, B, J, K, NQV
      NQV = NQ
      DO 30 A = 1, 3
         DO 10 B = 1, 3
            AJ(A, B) = ALAM*DV(A)*W(OFFHGG + 3*(A - 1) + B)
   10    CONTINUE
         AJ(A, A) = AJ(A, A) + 1.0D0
         DO 20 J = 1, NQV
            AJ(A, 3 + J) = ALAM*DV(A)*W(OFFHGQ + NQ*(A - 1) + J)
   20    CONTINUE
         AJ(A, M) = DV(A)*W(OFFDG + A)
   30 CONTINUE
      DO 60 J = 1, NQV
         DO 40 B = 1, 3
            AJ(3 + J, B) = -ALAM*W(OFFDHS + 3*(J - 1) + B)
   40    CONTINUE
         DO 50 K = 1, NQV
            AJ(3 + J, 3 + K) = -ALAM*W(OFFDHQ + NQ*(J - 1) + K)
   50    CONTINUE
         AJ(3 + J, 3 + J) = AJ(3 + J, 3 + J) + 1.0D0
         AJ(3 + J, M) = -W(OFFH + J)
   60 CONTINUE
      DO 70 B = 1, 3
         AJ(M, B) = W(OFFDF + B)
   70 CONTINUE
      DO 80 K = 1, NQV
         AJ(M, 3 + K) = W(OFFDFQ + K)
   80 CONTINUE
      AJ(M, M) = 0.0D0
      RETURN
      END
C ----------------------------------------------------------------------
C LU factorization with partial pivoting in place; .FALSE. if singular.
      LOGICAL FUNCTION @P@LU(AJ, IPIV)
      IMPLICIT NONE
@PARAMS@
      DOUBLE PRECISION AJ(M, M), BEST, T, AINV, AL
      INTEGER IPIV(M), C, R, K, J
      @P@LU = .FALSE.
      DO 50 C = 1, M
         BEST = ABS(AJ(C, C))
         K = C
         DO 10 R = C + 1, M
            IF (ABS(AJ(R, C)) .GT. BEST) THEN
               BEST = ABS(AJ(R, C))
               K = R
            END IF
   10    CONTINUE
         IPIV(C) = K
         IF (BEST .EQ. 0.0D0 .OR. .NOT. (BEST .LE. HUGE(1.0D0))) RETURN
         IF (K .NE. C) THEN
            DO 20 J = 1, M
               T = AJ(C, J)
               AJ(C, J) = AJ(K, J)
               AJ(K, J) = T
   20       CONTINUE
         END IF
         AINV = 1.0D0/AJ(C, C)
         DO 40 R = C + 1, M
            AJ(R, C) = AJ(R, C)*AINV
            AL = AJ(R, C)
            IF (AL .NE. 0.0D0) THEN
               DO 30 J = C + 1, M
                  AJ(R, J) = AJ(R, J) - AL*AJ(C, J)
   30          CONTINUE
            END IF
   40    CONTINUE
   50 CONTINUE
      @P@LU = .TRUE.
      RETURN
      END
C ----------------------------------------------------------------------
C Solve with the LU factors; B overwritten by the solution.
      SUBROUTINE @P@LS(AJ, IPIV, B)
      IMPLICIT NONE
@PARAMS@
      DOUBLE PRECISION AJ(M, M), B(M), T, ACC
      INTEGER IPIV(M), C, K, R, J
      DO 10 C = 1, M
         K = IPIV(C)
         IF (K .NE. C) THEN
            T = B(C)
            B(C) = B(K)
            B(K) = T
         END IF
   10 CONTINUE
      DO 30 R = 2, M
         ACC = B(R)
         DO 20 J = 1, R - 1
            ACC = ACC - AJ(R, J)*B(J)
   20    CONTINUE
         B(R) = ACC
   30 CONTINUE
      DO 50 R = M, 1, -1
         ACC = B(R)
         DO 40 J = R + 1, M
            ACC = ACC - AJ(R, J)*B(J)
   40    CONTINUE
         B(R) = ACC/AJ(R, R)
   50 CONTINUE
      RETURN
      END
C ----------------------------------------------------------------------
C Newton return of STR onto f = 0 from X = (STR, QN, 0); .TRUE. if it
C converged. Leaves the last iterate in X, the law's quantities in W.
      LOGICAL FUNCTION @P@NR(STR, QN, P, DV, X, W)
      IMPLICIT NONE
@PARAMS@
      DOUBLE PRECISION STR(3), QN(NQS), P(*), DV(3), X(M), W(*)
      DOUBLE PRECISION XK(M), ROWS(M), COLS(M), R(M), RK(M), STEP(M)
      DOUBLE PRECISION AJ(M, M), WK(NSIZE), F, DFN, FS, GS, ALAMS, QS
      DOUBLE PRECISION AMERIT, AMK, ALPHA
      INTEGER IPIV(M), A, B, J, K, IT, IH, NQV
      LOGICAL FULL, ACCEPT
      DOUBLE PRECISION @P@RS
      LOGICAL @P@LU
      EXTERNAL @P@RS, @P@LU
      NQV = NQ
      @P@NR = .FALSE.
      FULL = .TRUE.
      DO 5 K = 1, NSIZE
         WK(K) = 0.0D0
    5 CONTINUE
      F = MAX(SQRT(STR(1)**2 + STR(2)**2 + STR(3)**2), 1.0D-300)
      CALL @P@EV(STR(1), STR(2), STR(3), QN, P, W, 2)
      DFN = SQRT(W(OFFDF + 1)**2 + W(OFFDF + 2)**2 + W(OFFDF + 3)**2)
      FS = MAX(DFN*F, 1.0D-300)
      GS = MAX(SQRT((DV(1)*W(OFFDG + 1))**2 + (DV(2)*W(OFFDG + 2))**2
     &     + (DV(3)*W(OFFDG + 3))**2), 1.0D-300)
      ALAMS = F/GS
      DO 10 A = 1, 3
         ROWS(A) = 1.0D0/F
         COLS(A) = F
         X(A) = STR(A)
   10 CONTINUE
      DO 20 J = 1, NQV
         QS = MAX(MAX(ABS(W(OFFH + J))*ALAMS, ABS(QN(J))), 1.0D-300)
         ROWS(3 + J) = 1.0D0/QS
         COLS(3 + J) = QS
         X(3 + J) = QN(J)
   20 CONTINUE
      ROWS(M) = 1.0D0/FS
      COLS(M) = ALAMS
      X(M) = 0.0D0
      AMERIT = @P@RS(W, X, STR, QN, DV, ROWS, R)
      DO 90 IT = 1, 60
         IF (AMERIT .LE. 1.0D-13) GO TO 100
         IF (.NOT. FULL) CALL @P@EV(X(1), X(2), X(3), X(4), P, W, 2)
         CALL @P@JA(W, X(M), DV, AJ)
         DO 35 B = 1, M
            DO 30 A = 1, M
               AJ(A, B) = AJ(A, B)*ROWS(A)*COLS(B)
   30       CONTINUE
   35    CONTINUE
         IF (.NOT. @P@LU(AJ, IPIV)) RETURN
         DO 40 A = 1, M
            STEP(A) = -R(A)
   40    CONTINUE
         CALL @P@LS(AJ, IPIV, STEP)
         DO 50 A = 1, M
            STEP(A) = STEP(A)*COLS(A)
   50    CONTINUE
         ALPHA = 1.0D0
         ACCEPT = .FALSE.
         DO 80 IH = 1, 12
            DO 60 A = 1, M
               XK(A) = X(A) + ALPHA*STEP(A)
   60       CONTINUE
            CALL @P@EV(XK(1), XK(2), XK(3), XK(4), P, WK, 1)
            AMK = @P@RS(WK, XK, STR, QN, DV, ROWS, RK)
            IF (AMK .LE. (1.0D0 - 1.0D-4*ALPHA)*AMERIT) THEN
               DO 70 A = 1, M
                  X(A) = XK(A)
                  R(A) = RK(A)
   70          CONTINUE
               DO 75 K = 1, NSIZE
                  W(K) = WK(K)
   75          CONTINUE
               AMERIT = AMK
               FULL = .FALSE.
               ACCEPT = .TRUE.
               GO TO 85
            END IF
            ALPHA = 0.5D0*ALPHA
   80    CONTINUE
   85    IF (.NOT. ACCEPT) RETURN
   90 CONTINUE
  100 @P@NR = AMERIT .LE. 1.0D-13 .AND. X(M) .GE. 0.0D0
      RETURN
      END
C ----------------------------------------------------------------------
C Trial forces whose return ends at the apex SIGMA = 0 of a cone.
      LOGICAL FUNCTION @P@AX(STR, Q, P, DV, W)
      IMPLICIT NONE
@PARAMS@
      DOUBLE PRECISION STR(3), Q(NQS), P(*), DV(3), W(*), GT, TT
      @P@AX = .FALSE.
      CALL @P@EV(0.0D0, 0.0D0, 0.0D0, Q, P, W, 0)
      IF (W(1) .NE. 0.0D0) RETURN
      CALL @P@EV(STR(1), STR(2), 0.0D0, Q, P, W, 1)
      GT = SQRT(W(OFFDG + 1)**2 + W(OFFDG + 2)**2)
      TT = SQRT(STR(1)**2 + STR(2)**2)
      @P@AX = W(OFFDG + 3) .GT. 0.0D0 .AND.
     &     STR(3)*DV(1)*GT .LE. TT*DV(3)*W(OFFDG + 3)
      RETURN
      END
C ----------------------------------------------------------------------
C The return of closed trial forces STR (STR(3) > 0) at the stiffnesses
C DV: KIND = 0 elastic (SIG = STR), 1 plastic (SIG, Q1, DLAM and, when
C WANT, DSIG = dSIGMA/dSIGMA_trial), 3 apex of a cone, -1 failed.
      SUBROUTINE @P@RM(STR, QN, P, DV, SIG, Q1, DLAM, DSIG, WANT, KIND)
      IMPLICIT NONE
@PARAMS@
      DOUBLE PRECISION STR(3), QN(NQS), P(*), DV(3), SIG(3), Q1(NQS)
      DOUBLE PRECISION DLAM, DSIG(3, 3), X(M), W(NSIZE), AJ(M, M)
      DOUBLE PRECISION COL(M), ANTR
      INTEGER KIND, IPIV(M), A, C, J, NQV
      LOGICAL WANT, @P@NR, @P@AX, @P@LU
      EXTERNAL @P@NR, @P@AX, @P@LU
      NQV = NQ
      ANTR = SQRT(STR(1)**2 + STR(2)**2 + STR(3)**2)
      DO 10 J = 1, NQV
         Q1(J) = QN(J)
   10 CONTINUE
      DO 20 A = 1, 3
         SIG(A) = STR(A)
   20 CONTINUE
      DLAM = 0.0D0
      KIND = 0
      CALL @P@EV(STR(1), STR(2), STR(3), QN, P, W, 0)
      IF (W(1) .LE. 0.0D0) RETURN
      IF (.NOT. @P@NR(STR, QN, P, DV, X, W)) THEN
         KIND = -1
         IF (STR(3) .LE. 1.0D-13*ANTR) KIND = 3
         IF (KIND .EQ. -1) THEN
            IF (@P@AX(STR, QN, P, DV, W)) KIND = 3
         END IF
         RETURN
      END IF
      DLAM = X(M)
      KIND = 3
      IF (X(3) .LT. 0.0D0) RETURN
      IF (SQRT(X(1)**2 + X(2)**2 + X(3)**2) .LE. 1.0D-13*ANTR) RETURN
      KIND = 1
      DO 30 A = 1, 3
         SIG(A) = X(A)
   30 CONTINUE
      DO 40 J = 1, NQV
         Q1(J) = X(3 + J)
   40 CONTINUE
      IF (.NOT. WANT) RETURN
      CALL @P@EV(X(1), X(2), X(3), X(4), P, W, 2)
      CALL @P@JA(W, DLAM, DV, AJ)
      IF (.NOT. @P@LU(AJ, IPIV)) THEN
         KIND = -1
         RETURN
      END IF
      DO 70 C = 1, 3
         DO 50 A = 1, M
            COL(A) = 0.0D0
   50    CONTINUE
         COL(C) = 1.0D0
         CALL @P@LS(AJ, IPIV, COL)
         DO 60 A = 1, 3
            DSIG(A, C) = COL(A)
   60    CONTINUE
   70 CONTINUE
      RETURN
      END
"""

FRIC = """\
      SUBROUTINE FRIC(LM, TAU, DDTDDG, DDTDDP, DSLIP, SED, SFD,
     1 DDTDDT, PNEWDT, STATEV, DGAM, TAULM, PRESS, DPRESS, DDPDDH,
     2 SLIP, KSTEP, KINC, TIME, DTIME, NOEL, CINAME, SLNAME, MSNAME,
     3 NPT, NODE, NPATCH, COORDS, RCOORD, DROT, TEMP, PREDEF, NFDIR,
     4 MCRD, NPRED, NSTATV, CHRLNGTH, PROPS, NPROPS)
C
      INCLUDE 'ABA_PARAM.INC'
C
      CHARACTER*80 CINAME, SLNAME, MSNAME
      DIMENSION TAU(NFDIR), DDTDDG(NFDIR, NFDIR), DDTDDP(NFDIR),
     1 DSLIP(NFDIR), DDTDDT(NFDIR, 2), STATEV(*), DGAM(NFDIR),
     2 TAULM(NFDIR), SLIP(NFDIR), TIME(2), COORDS(MCRD),
     3 RCOORD(MCRD), DROT(2, 2), TEMP(2), PREDEF(2, *), PROPS(NPROPS)
C
@PARAMS@
      INTEGER NPAR
      PARAMETER (NPAR = @NPAR@)
      DOUBLE PRECISION Q0(NQS)
      DOUBLE PRECISION P(NPAR + 1), E(2), Q(NQS), EN(2), QN(NQS)
      DOUBLE PRECISION STR(3), SIG(3), DSIG(3, 3), DV(3), DG(2), ET(2)
      DOUBLE PRECISION AKT, PSTART, PK, FRAC, DLAM, DISS
      INTEGER KIND, IDEPTH, IPOS, IFULL, I, J, NQV, KAP
      DATA Q0 /@Q0@/
      NQV = NQ
      KAP = KAPPA
      IF (.FALSE.) WRITE (*, *) TAULM(1), SLIP(1), KSTEP, KINC, TIME,
     &     DTIME, NOEL, CINAME, SLNAME, MSNAME, NPT, NODE, NPATCH,
     &     COORDS(1), RCOORD(1), DROT(1, 1), TEMP(1), PREDEF(1, 1),
     &     NPRED, CHRLNGTH, DDPDDH
C     Open at the previous increment: nothing to do.
      IF (LM .EQ. 2) RETURN
      LM = 0
      IF (NPROPS .LT. NPAR + 1 .OR. NSTATV .LT. NQ + 2) THEN
         WRITE (*, *) 'FRIC (frictionrules): needs PROPERTIES = ',
     &        NPAR + 1, ' and DEPVAR = ', NQ + 2
         CALL XIT
      END IF
      DO 10 I = 1, NPAR + 1
         P(I) = PROPS(I)
   10 CONTINUE
      AKT = PROPS(NPAR + 1)
      DO 20 J = 1, NQV
         Q(J) = STATEV(J) + Q0(J)
   20 CONTINUE
      E(1) = STATEV(NQ + 1)
      E(2) = STATEV(NQ + 2)
      DG(1) = DGAM(1)
      DG(2) = 0.0D0
      DV(1) = AKT
      DV(2) = 0.0D0
      DV(3) = 0.0D0
      IF (NFDIR .EQ. 2) THEN
         DG(2) = DGAM(2)
         DV(2) = AKT
      ELSE
         E(2) = 0.0D0
      END IF
      DO 30 I = 1, NFDIR
         TAU(I) = 0.0D0
         DDTDDP(I) = 0.0D0
         DSLIP(I) = 0.0D0
         DDTDDT(I, 1) = 0.0D0
         DDTDDT(I, 2) = 0.0D0
         DO 25 J = 1, NFDIR
            DDTDDG(I, J) = 0.0D0
   25    CONTINUE
   30 CONTINUE
      SED = 0.0D0
      SFD = 0.0D0
C     Substeps where Newton fails (halving, depth 10), the pressure
C     linear over the increment from PRESS - DPRESS to PRESS.
      PSTART = PRESS - DPRESS
      IFULL = 1024
      IPOS = 0
      IDEPTH = 0
      KIND = 2
   40 IF (IPOS .GE. IFULL) GO TO 90
      FRAC = 1.0D0/2**IDEPTH
      PK = PSTART + DPRESS*DBLE(IPOS + IFULL/2**IDEPTH)/DBLE(IFULL)
      ET(1) = E(1) + FRAC*DG(1)
      ET(2) = E(2) + FRAC*DG(2)
      DO 50 J = 1, NQV
         QN(J) = Q(J)
   50 CONTINUE
      DISS = 0.0D0
      IF (PK .LE. 0.0D0) THEN
         KIND = 2
         EN(1) = 0.0D0
         EN(2) = 0.0D0
         SIG(1) = 0.0D0
         SIG(2) = 0.0D0
      ELSE
         STR(1) = AKT*ET(1)
         STR(2) = AKT*ET(2)
         STR(3) = PK
         CALL @P@RM(STR, Q, P, DV, SIG, QN, DLAM, DSIG, .TRUE., KIND)
         IF (KIND .EQ. -1) THEN
            IF (IDEPTH .GE. 10) THEN
               PNEWDT = 0.25D0
               RETURN
            END IF
            IDEPTH = IDEPTH + 1
            GO TO 40
         END IF
         IF (KIND .EQ. 0) THEN
            EN(1) = ET(1)
            EN(2) = ET(2)
         ELSE IF (KIND .EQ. 1) THEN
            EN(1) = SIG(1)/AKT
            EN(2) = SIG(2)/AKT
            DISS = SIG(1)*(ET(1) - EN(1)) + SIG(2)*(ET(2) - EN(2))
         ELSE
            EN(1) = 0.0D0
            EN(2) = 0.0D0
            SIG(1) = 0.0D0
            SIG(2) = 0.0D0
            IF (KAP .GE. 0) QN(KAP + 1) = Q(KAP + 1)
     &           + SQRT(ET(1)**2 + ET(2)**2)
         END IF
      END IF
      DO 60 I = 1, NFDIR
         DSLIP(I) = DSLIP(I) + ET(I) - EN(I)
   60 CONTINUE
      SFD = SFD + DISS
      E(1) = EN(1)
      E(2) = EN(2)
      DO 70 J = 1, NQV
         Q(J) = QN(J)
   70 CONTINUE
      IPOS = IPOS + IFULL/2**IDEPTH
   80 IF (IDEPTH .GT. 0) THEN
         IF (MOD(IPOS, IFULL/2**(IDEPTH - 1)) .EQ. 0) THEN
            IDEPTH = IDEPTH - 1
            GO TO 80
         END IF
      END IF
      GO TO 40
C     The end of the increment: forces, tangent of the last substep.
   90 DO 110 I = 1, NFDIR
         TAU(I) = SIG(I)
         IF (KIND .EQ. 0) THEN
            DDTDDG(I, I) = AKT
         ELSE IF (KIND .EQ. 1) THEN
            DDTDDP(I) = DSIG(I, 3)
            DO 100 J = 1, NFDIR
               DDTDDG(I, J) = DSIG(I, J)*AKT
  100       CONTINUE
         END IF
  110 CONTINUE
      SED = 0.5D0*AKT*(E(1)**2 + E(2)**2)
      DO 120 J = 1, NQV
         STATEV(J) = Q(J) - Q0(J)
  120 CONTINUE
      STATEV(NQ + 1) = E(1)
      STATEV(NQ + 2) = E(2)
      RETURN
      END
"""

UINTER = """\
      SUBROUTINE UINTER(STRESS, DDSDDR, FLUX, DDFDDT, DDSDDT, DDFDDR,
     1 STATEV, SED, SFD, SPD, SVD, SCD, PNEWDT, RDISP, DRDISP,
     2 TEMP, DTEMP, PREDEF, DPRED, TIME, DTIME, FREQR, CINAME, SLNAME,
     3 MSNAME, PROPS, COORDS, ALOCALDIR, DROT, AREA, CHRLNGTH, NODE,
     4 NDIR, NSTATV, NPRED, NPROPS, MCRD, KSTEP, KINC, KIT, LINPER,
     5 LOPENCLOSE, LSTATE, LSDI, LPRINT)
C
      INCLUDE 'ABA_PARAM.INC'
C
      CHARACTER*80 CINAME, SLNAME, MSNAME
      DIMENSION STRESS(NDIR), DDSDDR(NDIR, NDIR), FLUX(2),
     1 DDFDDT(2, 2), DDSDDT(NDIR, 2), DDFDDR(2, NDIR), STATEV(NSTATV),
     2 RDISP(NDIR), DRDISP(NDIR), TEMP(2), DTEMP(2), PREDEF(2, NPRED),
     3 DPRED(2, NPRED), TIME(2), PROPS(NPROPS), COORDS(MCRD),
     4 ALOCALDIR(3, 3), DROT(2, 2)
C
@PARAMS@
      INTEGER NPAR
      PARAMETER (NPAR = @NPAR@)
      DOUBLE PRECISION Q0(NQS)
      DOUBLE PRECISION P(NPAR + 2), E(3), PL(3), Q(NQS), QN(NQS)
      DOUBLE PRECISION DU(3), ET(3), EN(3), STR(3), SIG(3), DSIG(3, 3)
      DOUBLE PRECISION DV(3), C(3, 3), EK(3), AKT, AKN, FRAC, DLAM
      DOUBLE PRECISION DISST, DISSN
      INTEGER KIND, IDEPTH, IPOS, IFULL, I, J, NQV, KAP, IS(3), IR(3)
      DATA IS /3, 1, 2/, IR /3, 1, 2/
      DATA Q0 /@Q0@/
      NQV = NQ
      KAP = KAPPA
      IF (.FALSE.) WRITE (*, *) TEMP(1), DTEMP(1), PREDEF(1, 1),
     &     DPRED(1, 1), TIME(1), DTIME, FREQR, CINAME, SLNAME, MSNAME,
     &     COORDS(1), ALOCALDIR(1, 1), DROT(1, 1), AREA, CHRLNGTH,
     &     NODE, KSTEP, KINC, KIT, LINPER, LPRINT, RDISP(1)
      IF (NPROPS .LT. NPAR + 2 .OR. NSTATV .LT. NQ + 6) THEN
         WRITE (*, *) 'UINTER (frictionrules): needs PROPERTIES = ',
     &        NPAR + 2, ' and DEPVAR = ', NQ + 6
         CALL XIT
      END IF
      DO 10 I = 1, NPAR + 2
         P(I) = PROPS(I)
   10 CONTINUE
      AKN = PROPS(NPAR + 1)
      AKT = PROPS(NPAR + 2)
      DO 20 I = 1, 3
         E(I) = STATEV(NQ + I)
         PL(I) = STATEV(NQ + 3 + I)
   20 CONTINUE
      DO 30 J = 1, NQV
         Q(J) = STATEV(J) + Q0(J)
   30 CONTINUE
C     (dt1, dt2, dn) with dn positive on opening; RDISP(1) is the
C     overclosure.
      DU(1) = DRDISP(2)
      DU(2) = 0.0D0
      DU(3) = -DRDISP(1)
      DV(1) = AKT
      DV(2) = 0.0D0
      DV(3) = AKN
      IF (NDIR .EQ. 3) THEN
         DU(2) = DRDISP(3)
         DV(2) = AKT
      END IF
      EK(1) = AKT
      EK(2) = AKT
      EK(3) = -AKN
      SFD = 0.0D0
      SPD = 0.0D0
      SVD = 0.0D0
      SCD = 0.0D0
C     Substeps where Newton fails (halving, depth 10).
      IFULL = 1024
      IPOS = 0
      IDEPTH = 0
      KIND = 2
   40 IF (IPOS .GE. IFULL) GO TO 90
      FRAC = 1.0D0/2**IDEPTH
      DO 45 I = 1, 3
         ET(I) = E(I) + FRAC*DU(I)
   45 CONTINUE
      DO 50 J = 1, NQV
         QN(J) = Q(J)
   50 CONTINUE
      DISST = 0.0D0
      DISSN = 0.0D0
      STR(1) = AKT*ET(1)
      STR(2) = AKT*ET(2)
      STR(3) = -AKN*ET(3)
      KIND = 2
      IF (STR(3) .GT. 0.0D0) THEN
         CALL @P@RM(STR, Q, P, DV, SIG, QN, DLAM, DSIG, .TRUE., KIND)
         IF (KIND .EQ. -1) THEN
            IF (IDEPTH .GE. 10) THEN
               PNEWDT = 0.25D0
               RETURN
            END IF
            IDEPTH = IDEPTH + 1
            GO TO 40
         END IF
      END IF
      IF (KIND .EQ. 0) THEN
         DO 55 I = 1, 3
            EN(I) = ET(I)
   55    CONTINUE
      ELSE IF (KIND .EQ. 1) THEN
         EN(1) = SIG(1)/AKT
         EN(2) = SIG(2)/AKT
         EN(3) = -SIG(3)/AKN
         DISST = SIG(1)*(ET(1) - EN(1)) + SIG(2)*(ET(2) - EN(2))
         DISSN = -SIG(3)*(ET(3) - EN(3))
      ELSE
C        Open, or a return that ends at the apex of a cone.
         DO 60 I = 1, 3
            SIG(I) = 0.0D0
   60    CONTINUE
         EN(1) = 0.0D0
         EN(2) = 0.0D0
         EN(3) = MAX(ET(3), 0.0D0)
         DO 62 J = 1, NQV
            QN(J) = Q(J)
   62    CONTINUE
         IF (KIND .EQ. 3 .AND. KAP .GE. 0) QN(KAP + 1) = Q(KAP + 1)
     &        + SQRT(ET(1)**2 + ET(2)**2)
         IF (KIND .EQ. 3) KIND = 2
      END IF
      DO 65 I = 1, 3
         PL(I) = PL(I) + ET(I) - EN(I)
         E(I) = EN(I)
   65 CONTINUE
      DO 70 J = 1, NQV
         Q(J) = QN(J)
   70 CONTINUE
      SFD = SFD + DISST
      SPD = SPD + DISSN
      IPOS = IPOS + IFULL/2**IDEPTH
   80 IF (IDEPTH .GT. 0) THEN
         IF (MOD(IPOS, IFULL/2**(IDEPTH - 1)) .EQ. 0) THEN
            IDEPTH = IDEPTH - 1
            GO TO 80
         END IF
      END IF
      GO TO 40
C     The end of the increment: stress (pressure, shear 1, shear 2) and
C     d(stress)/d(overclosure, slip 1, slip 2) of the last substep.
   90 DO 110 I = 1, 3
         DO 100 J = 1, 3
            C(I, J) = 0.0D0
            IF (KIND .EQ. 1) C(I, J) = DSIG(I, J)*EK(J)
  100    CONTINUE
         IF (KIND .EQ. 0) C(I, I) = EK(I)
  110 CONTINUE
      DO 130 I = 1, NDIR
         STRESS(I) = SIG(IS(I))
         IF (KIND .EQ. 2) STRESS(I) = 0.0D0
         DO 120 J = 1, NDIR
            DDSDDR(I, J) = C(IS(I), IR(J))
            IF (J .EQ. 1) DDSDDR(I, J) = -DDSDDR(I, J)
  120    CONTINUE
         DDSDDT(I, 1) = 0.0D0
         DDSDDT(I, 2) = 0.0D0
         DDFDDR(1, I) = 0.0D0
         DDFDDR(2, I) = 0.0D0
  130 CONTINUE
      FLUX(1) = 0.0D0
      FLUX(2) = 0.0D0
      DDFDDT(1, 1) = 0.0D0
      DDFDDT(1, 2) = 0.0D0
      DDFDDT(2, 1) = 0.0D0
      DDFDDT(2, 2) = 0.0D0
      SED = 0.5D0*(AKT*(E(1)**2 + E(2)**2) + AKN*E(3)**2)
      IF (KIND .EQ. 2) SED = 0.0D0
      LSTATE = 1
      IF (KIND .EQ. 2) LSTATE = 0
      LSDI = 0
      IF (LOPENCLOSE .NE. -1 .AND. LOPENCLOSE .NE. LSTATE) LSDI = 1
      DO 140 J = 1, NQV
         STATEV(J) = Q(J) - Q0(J)
  140 CONTINUE
      DO 150 I = 1, 3
         STATEV(NQ + I) = E(I)
         STATEV(NQ + 3 + I) = PL(I)
  150 CONTINUE
      RETURN
      END
"""

INVERSE = """\
C ----------------------------------------------------------------------
C The inverse relation at N = 1: the force T on the limit surface whose
C tangential slip direction is (C, S) (a unit vector); with I2D = 1 the
C force along (C, S) only (2-D). IOK = 0 where Newton fails.
      SUBROUTINE @P@IR(C, S, I2D, Q, P, T, IOK)
      IMPLICIT NONE
@PARAMS@
      DOUBLE PRECISION C, S, Q(NQS), P(*), T(2), W(NSIZE), WK(NSIZE)
      DOUBLE PRECISION R, PHI, DPHI, R1, R2, A11, A12, A21, A22, DET
      DOUBLE PRECISION D1, D2, TK1, TK2, AMER, AMK, ALPHA, SC
      INTEGER I2D, IOK, IT, IH, K
      LOGICAL ACCEPT
      IOK = 0
      R = 1.0D0
      DO 10 IT = 1, 200
         CALL @P@EV(R*C, R*S, 1.0D0, Q, P, W, 1)
         PHI = W(1)
         DPHI = W(OFFDF + 1)*C + W(OFFDF + 2)*S
         IF (ABS(PHI) .LE. 1.0D-15*(1.0D0 + R)) GO TO 20
         IF (.NOT. (DPHI .GT. 0.0D0)) RETURN
         IF (R - PHI/DPHI .LE. 0.0D0) THEN
            R = 0.5D0*R
         ELSE
            R = R - PHI/DPHI
         END IF
   10 CONTINUE
      RETURN
   20 T(1) = R*C
      T(2) = R*S
      IF (I2D .EQ. 1) THEN
         IOK = 1
         RETURN
      END IF
C     f = 0 and grad_T g parallel to (C, S): Newton with line search.
      SC = 1.0D0/MAX(SQRT(W(OFFDF + 1)**2 + W(OFFDF + 2)**2), 1.0D-300)
      CALL @P@EV(T(1), T(2), 1.0D0, Q, P, W, 2)
      R1 = W(1)*SC
      R2 = W(OFFDG + 1)*S - W(OFFDG + 2)*C
      AMER = SQRT(R1*R1 + R2*R2)
      DO 50 IT = 1, 60
         IF (AMER .LE. 1.0D-14) GO TO 60
         A11 = W(OFFDF + 1)*SC
         A12 = W(OFFDF + 2)*SC
         A21 = W(OFFHGG + 1)*S - W(OFFHGG + 4)*C
         A22 = W(OFFHGG + 2)*S - W(OFFHGG + 5)*C
         DET = A11*A22 - A12*A21
         IF (.NOT. (ABS(DET) .GT. 1.0D-300)) RETURN
         D1 = -(A22*R1 - A12*R2)/DET
         D2 = -(A11*R2 - A21*R1)/DET
         ALPHA = 1.0D0
         ACCEPT = .FALSE.
         DO 40 IH = 1, 30
            TK1 = T(1) + ALPHA*D1
            TK2 = T(2) + ALPHA*D2
            CALL @P@EV(TK1, TK2, 1.0D0, Q, P, WK, 2)
            R1 = WK(1)*SC
            R2 = WK(OFFDG + 1)*S - WK(OFFDG + 2)*C
            AMK = SQRT(R1*R1 + R2*R2)
            IF (AMK .LE. (1.0D0 - 1.0D-4*ALPHA)*AMER) THEN
               T(1) = TK1
               T(2) = TK2
               AMER = AMK
               DO 30 K = 1, NSIZE
                  W(K) = WK(K)
   30          CONTINUE
               ACCEPT = .TRUE.
               GO TO 45
            END IF
            ALPHA = 0.5D0*ALPHA
   40    CONTINUE
   45    IF (.NOT. ACCEPT) RETURN
   50 CONTINUE
      RETURN
   60 IF (W(OFFDG + 1)*C + W(OFFDG + 2)*S .GT. 0.0D0) IOK = 1
      RETURN
      END
C ----------------------------------------------------------------------
C Internal variables after a slip DLAM, as changes from the virgin Q0:
C QOUT = Q + DLAM H - Q0 (H in W).
      SUBROUTINE @P@UQ(Q, Q0, W, DLAM, QOUT)
      IMPLICIT NONE
@PARAMS@
      DOUBLE PRECISION Q(NQS), Q0(NQS), W(*), DLAM, QOUT(*)
      INTEGER J, NQV
      NQV = NQ
      DO 10 J = 1, NQV
         QOUT(J) = Q(J) + DLAM*W(OFFH + J) - Q0(J)
   10 CONTINUE
      RETURN
      END
"""

VFRIC = """\
      SUBROUTINE VFRIC(
C Write only -
     *     fTangential,
C Read/Write -
     *     state,
C Read only -
     *     nBlock, nBlockAnal, nBlockEdge,
     *     nNodState, nNodSlv, nNodMst,
     *     nFricDir, nDir,
     *     nStates, nProps, nTemp, nFields,
     *     jFlags, rData,
     *     surfInt, surfSlv, surfMst,
     *     jConSlvUid, jConMstUid, props,
     *     dSlipFric, fStickForce, fTangPrev, fNormal,
     *     areaCont, dircosN, dircosSl,
     *     shapeSlv, shapeMst,
     *     coordSlv, coordMst,
     *     velSlv, velMst,
     *     tempSlv, tempMst,
     *     fieldSlv, fieldMst )
C
      INCLUDE 'vaba_param.inc'
C
      DIMENSION fTangential(nFricDir, nBlock),
     *     state(nStates, nNodState, nBlock),
     *     jConSlvUid(nNodSlv, nBlock),
     *     jConMstUid(nNodMst, nBlockAnal),
     *     props(nProps),
     *     dSlipFric(nDir, nBlock),
     *     fStickForce(nBlock),
     *     fTangPrev(nDir, nBlock),
     *     fNormal(nBlock),
     *     areaCont(nBlock),
     *     dircosN(nDir, nBlock),
     *     dircosSl(nDir, nBlock),
     *     shapeSlv(nNodSlv, nBlockEdge),
     *     shapeMst(nNodMst, nBlockAnal),
     *     coordSlv(nDir, nNodSlv, nBlockAnal),
     *     coordMst(nDir, nNodMst, nBlockAnal),
     *     velSlv(nDir, nNodSlv, nBlockAnal),
     *     velMst(nDir, nNodMst, nBlockAnal),
     *     tempSlv(nBlockAnal),
     *     tempMst(nBlockAnal),
     *     fieldSlv(nFields, nBlockAnal),
     *     fieldMst(nFields, nBlockAnal)
      PARAMETER (nFlags = 3, nData = 4)
      DIMENSION jFlags(nFlags), rData(nData)
      CHARACTER*80 surfInt, surfSlv, surfMst
C
@PARAMS@
      INTEGER NPAR
      PARAMETER (NPAR = @NPAR@)
      DOUBLE PRECISION Q0(NQS)
      DOUBLE PRECISION P(NPAR + 1), Q(NQS), W(NSIZE), T(2), AN(3)
      DOUBLE PRECISION SL(3), REF(3), B1(3), B2(3), AM1(3), AM2(3)
      DOUBLE PRECISION G(3), S2(3), PHI, CS, SN, FN, F1, F2, FMAG
      DOUBLE PRECISION SCALE, DOT, ALEN, GT, DLAM, DS
      INTEGER KB, I, J, I2D, IOK, NQV
      DATA Q0 /@Q0@/
      NQV = NQ
      IF (.FALSE.) WRITE (*, *) nTemp, jFlags(1), rData(1), surfInt,
     &     surfSlv, surfMst, jConSlvUid(1, 1), jConMstUid(1, 1),
     &     fTangPrev(1, 1), areaCont(1), shapeSlv(1, 1),
     &     shapeMst(1, 1), coordSlv(1, 1, 1), coordMst(1, 1, 1),
     &     velSlv(1, 1, 1), velMst(1, 1, 1), tempSlv(1), tempMst(1),
     &     fieldSlv(1, 1), fieldMst(1, 1)
      IF (nProps .LT. NPAR + 1 .OR. nStates .LT. NQ) THEN
         WRITE (*, *) 'VFRIC (frictionrules): needs PROPERTIES = ',
     &        NPAR + 1, ' and DEPVAR = ', NQ
         CALL XPLB_EXIT
      END IF
      DO 10 I = 1, NPAR + 1
         P(I) = props(I)
   10 CONTINUE
      PHI = props(NPAR + 1)
      DO 200 KB = 1, nBlock
         DO 20 I = 1, nFricDir
            fTangential(I, KB) = 0.0D0
   20    CONTINUE
         FN = fNormal(KB)
         IF (.NOT. (FN .GT. 0.0D0)) GO TO 200
         DO 30 J = 1, NQV
            Q(J) = state(J, 1, KB) + Q0(J)
   30    CONTINUE
         AN(3) = 0.0D0
         SL(3) = 0.0D0
         DO 40 I = 1, nDir
            AN(I) = dircosN(I, KB)
            SL(I) = dircosSl(I, KB)
   40    CONTINUE
         IF (nDir .EQ. 3) THEN
C           Material frame: global 1 (or 2 where the normal is closer to
C           it) projected on the tangent plane, turned by PHI about N.
            REF(1) = 1.0D0
            REF(2) = 0.0D0
            REF(3) = 0.0D0
            IF (ABS(AN(1)) .GT. SQRT(0.5D0)) THEN
               REF(1) = 0.0D0
               REF(2) = 1.0D0
            END IF
            DOT = REF(1)*AN(1) + REF(2)*AN(2) + REF(3)*AN(3)
            DO 50 I = 1, 3
               B1(I) = REF(I) - DOT*AN(I)
   50       CONTINUE
            ALEN = SQRT(B1(1)**2 + B1(2)**2 + B1(3)**2)
            DO 60 I = 1, 3
               B1(I) = B1(I)/ALEN
   60       CONTINUE
            B2(1) = AN(2)*B1(3) - AN(3)*B1(2)
            B2(2) = AN(3)*B1(1) - AN(1)*B1(3)
            B2(3) = AN(1)*B1(2) - AN(2)*B1(1)
            DO 70 I = 1, 3
               AM1(I) = COS(PHI)*B1(I) + SIN(PHI)*B2(I)
               AM2(I) = -SIN(PHI)*B1(I) + COS(PHI)*B2(I)
   70       CONTINUE
            I2D = 0
         ELSE
C           2-D: the tangent (N2, -N1) turned by PHI = 0 or pi.
            AM1(1) = COS(PHI)*AN(2)
            AM1(2) = -COS(PHI)*AN(1)
            AM1(3) = 0.0D0
            AM2(1) = 0.0D0
            AM2(2) = 0.0D0
            AM2(3) = 0.0D0
            I2D = 1
         END IF
         CS = SL(1)*AM1(1) + SL(2)*AM1(2) + SL(3)*AM1(3)
         SN = SL(1)*AM2(1) + SL(2)*AM2(2) + SL(3)*AM2(3)
         ALEN = SQRT(CS*CS + SN*SN)
         IF (.NOT. (ALEN .GT. 0.0D0)) GO TO 200
         CS = CS/ALEN
         SN = SN/ALEN
         CALL @P@IR(CS, SN, I2D, Q, P, T, IOK)
         IF (IOK .EQ. 0) THEN
C           No force slides that way (or no convergence): stick.
            fTangential(1, KB) = -fStickForce(KB)
            GO TO 200
         END IF
C        The force for the slip direction, scaled by the normal force,
C        in the slip frame (1 along the slip, 2 = N x slip).
         DO 80 I = 1, 3
            G(I) = FN*(T(1)*AM1(I) + T(2)*AM2(I))
   80    CONTINUE
         S2(1) = AN(2)*SL(3) - AN(3)*SL(2)
         S2(2) = AN(3)*SL(1) - AN(1)*SL(3)
         S2(3) = AN(1)*SL(2) - AN(2)*SL(1)
         F1 = G(1)*SL(1) + G(2)*SL(2) + G(3)*SL(3)
         F2 = G(1)*S2(1) + G(2)*S2(2) + G(3)*S2(3)
         IF (nFricDir .EQ. 1) F2 = 0.0D0
         FMAG = SQRT(F1*F1 + F2*F2)
         SCALE = 1.0D0
         IF (FMAG .GT. fStickForce(KB)) THEN
            SCALE = fStickForce(KB)/FMAG
         END IF
         fTangential(1, KB) = -SCALE*F1
         IF (nFricDir .EQ. 2) fTangential(2, KB) = -SCALE*F2
C        Internal variables: dq = dlambda h, dlambda = |dslip|/|dg/dT|.
         IF (NQV .GT. 0 .AND. SCALE .EQ. 1.0D0) THEN
            DS = 0.0D0
            DO 90 I = 1, nDir
               DS = DS + dSlipFric(I, KB)**2
   90       CONTINUE
            DS = SQRT(DS)
            CALL @P@EV(FN*T(1), FN*T(2), FN, Q, P, W, 1)
            GT = SQRT(W(OFFDG + 1)**2 + W(OFFDG + 2)**2)
            DLAM = 0.0D0
            IF (GT .GT. 0.0D0) DLAM = DS/GT
            CALL @P@UQ(Q, Q0, W, DLAM, state(1, 1, KB))
         END IF
  200 CONTINUE
      RETURN
      END
"""
